/* Markdown reference of a command, generated from its declared option
 * tables, so doc/cli.md never disagrees with --help (doc/cli.sh). */
#include "config.h"

#include <stdio.h>
#include <string.h>

#include "options.h"

static void cell(const char *text)
{
    for (const char *p = text ? text : ""; *p; ++p)
        fputs(*p == '|' ? "\\|" : (char[2]){*p, 0}, stdout);
}

void opt_print_markdown(const opt_spec *const *tables, const char *command, const char *usage,
                        const char *summary)
{
    printf("## `%s`\n\n```\n%s\n```\n\n%s\n\n", command, usage, summary);
    printf("| option | value | default | meaning |\n|---|---|---|---|\n");
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s) {
            printf("| `%s%s` | ", opt_dash(s->name), s->name);
            if (s->type == OPT_CHOICE)
                cell(s->choices);
            else if (s->type != OPT_FLAG)
                cell(s->metavar);
            printf(" | ");
            if (s->default_text && s->type != OPT_FLAG)
                cell(s->default_text);
            printf(" | ");
            cell(s->help);
            printf(" |\n");
        }
    printf("\n");
}
