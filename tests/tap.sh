# TAP helpers for shell tests (sourced). Each check prints "ok N - ..." or
# "not ok N - ..."; tap_done prints the plan and sets the exit status.
tap_n=0
tap_failed=0

tap_ok() { # CONDITION_STATUS DESCRIPTION...
    local status=$1
    shift
    tap_n=$((tap_n + 1))
    if [ "$status" -eq 0 ]; then
        echo "ok $tap_n - $*"
    else
        echo "not ok $tap_n - $*"
        tap_failed=$((tap_failed + 1))
    fi
}

tap_skip() { # DESCRIPTION REASON
    tap_n=$((tap_n + 1))
    echo "ok $tap_n - $1 # SKIP $2"
}

tap_diag() {
    echo "# $*"
}

tap_done() {
    echo "1..$tap_n"
    [ "$tap_failed" -eq 0 ]
}
