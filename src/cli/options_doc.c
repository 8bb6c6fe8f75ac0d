/* A command's reference in other forms, generated from its declared option
 * tables so that none disagrees with --help: Markdown for doc/cli.md
 * (doc/cli.sh), a man page (man/skysweep-COMMAND.1), the words bash
 * completes (completion/skysweep, doc/completion.sh) and JSON for the front
 * ends (the Python package's file calls). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "options.h"
#include "skysweep_products.h"

static void cell(const char *text)
{
    for (const char *p = text ? text : ""; *p; ++p)
        fputs(*p == '|' ? "\\|" : (char[2]){*p, 0}, stdout);
}

/* The tables' basic or advanced options as a Markdown table. */
static void markdown_table(const opt_spec *const *tables, int advanced)
{
    if (advanced)
        printf("%s:\n\n", OPT_ADVANCED_HEADING);
    printf("| option | value | default | meaning |\n|---|---|---|---|\n");
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s) {
            if (opt_advanced(s->name) != advanced)
                continue;
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

void opt_print_markdown(const opt_spec *const *tables, const char *command, const char *usage,
                        const char *summary)
{
    printf("## `%s`\n\n```\n%s\n```\n\n%s\n\n", command, usage, summary);
    markdown_table(tables, 0);
    if (opt_any_advanced(tables))
        markdown_table(tables, 1);
}

/* Text for roff: backslashes escaped, dashes as \-, and a line that
 * would start with a control character protected. */
static void roff(const char *text)
{
    int line_start = 1;
    for (const char *p = text ? text : ""; *p; ++p) {
        if (line_start && (*p == '.' || *p == '\''))
            fputs("\\&", stdout);
        if (*p == '\\')
            fputs("\\e", stdout);
        else if (*p == '-')
            fputs("\\-", stdout);
        else
            putchar(*p);
        line_start = *p == '\n';
    }
}

static void man_option(const opt_spec *s)
{
    printf(".TP\n.B ");
    roff(opt_dash(s->name));
    roff(s->name);
    if (s->type != OPT_FLAG) {
        printf(" \\fI");
        roff(s->type == OPT_CHOICE ? s->choices : s->metavar);
        printf("\\fR");
    }
    printf("\n");
    roff(s->help);
    if (s->default_text && s->type != OPT_FLAG) {
        printf(" (default ");
        roff(s->default_text);
        printf(")");
    }
    printf("\n");
}

void opt_print_man(const opt_spec *const *tables, const char *command, const char *usage,
                   const char *summary, const char *version)
{
    char upper[64];
    snprintf(upper, sizeof upper, "SKYSWEEP-%s", command);
    for (char *c = upper; *c; ++c)
        *c = (char)(*c >= 'a' && *c <= 'z' ? *c - 'a' + 'A' : *c);
    printf(".TH %s 1 \"\" \"skysweep %s\" \"skysweep manual\"\n", upper, version);
    printf(".SH NAME\nskysweep\\-%s \\- ", command);
    /* The summary's first sentence: up to a full stop before a space or a line's end. */
    const char *end = summary;
    while ((end = strchr(end, '.')) && end[1] && end[1] != ' ' && end[1] != '\n')
        ++end;
    char first[400];
    snprintf(first, sizeof first, "%.*s", end ? (int)(end - summary) : (int)strlen(summary),
             summary);
    for (char *c = first; *c; ++c)
        *c = *c == '\n' ? ' ' : *c;
    first[0] = (char)(first[0] >= 'A' && first[0] <= 'Z' ? first[0] - 'A' + 'a' : first[0]);
    roff(first);
    printf("\n.SH SYNOPSIS\n.nf\n");
    roff(usage);
    printf("\n.fi\n.SH DESCRIPTION\n");
    roff(summary);
    printf("\n.SH OPTIONS\n");
    for (int advanced = 0; advanced < 2; ++advanced) {
        if (advanced && opt_any_advanced(tables))
            printf(".SS \"%s\"\n", OPT_ADVANCED_HEADING);
        for (int t = 0; tables[t]; ++t)
            for (const opt_spec *s = tables[t]; s->name; ++s)
                if (opt_advanced(s->name) == advanced)
                    man_option(s);
        if (!advanced)
            printf(".TP\n.B \\-\\-help\nshow this help\n");
    }
    printf(".SH SEE ALSO\n.BR skysweep (1);\n"
           "doc/cli.md in the source tree has every command's options in one place.\n");
}

void opt_print_completion(const opt_spec *const *tables)
{
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s) {
            printf("%s%s", opt_dash(s->name), s->name);
            if (s->type == OPT_CHOICE) {
                putchar(' ');
                for (const char *c = s->choices; *c; ++c)
                    putchar(*c == '|' ? ' ' : *c);
            }
            else if (s->type != OPT_FLAG)
                printf(" %s", s->type == OPT_INPUT || s->type == OPT_OUTPUT ? "<file>" : "<value>");
            printf("\n");
        }
    printf("--help\n");
}

/* A JSON string: quotes, backslashes and control characters escaped. */
static void json_string(const char *text)
{
    putchar('"');
    for (const unsigned char *p = (const unsigned char *)(text ? text : ""); *p; ++p) {
        if (*p == '"' || *p == '\\')
            printf("\\%c", *p);
        else if (*p == '\n')
            fputs("\\n", stdout);
        else if (*p < 0x20)
            printf("\\u%04x", *p);
        else
            putchar(*p);
    }
    putchar('"');
}

/* A JSON number, or null where JSON has none (infinities, NaN). */
static void json_number(double v)
{
    if (isfinite(v))
        printf("%.17g", v);
    else
        printf("null");
}

/* A product's face from the registry (skysweep_products.h): its label,
 * group and outputs, each marked "output": true, so that front ends make
 * their output parameters and algorithms from the library's declaration. */
static void print_json_product(const ss_product_info *product)
{
    if (!product)
        return;
    printf(", \"title\": ");
    json_string(product->title);
    printf(", \"group\": ");
    json_string(product->group);
    printf(", \"outputs\": [");
    for (const ss_product_output *o = product->outputs; o->name; ++o) {
        printf("%s\n  {\"name\": ", o == product->outputs ? "" : ",");
        json_string(o->name);
        if (o->option) {
            printf(", \"option\": ");
            json_string(o->option);
        }
        printf(", \"unit\": ");
        json_string(o->unit);
        printf(", \"bands\": %d, \"band_names\": [", o->bands);
        for (const char *c = o->band_names; *c;) {
            size_t len = strcspn(c, "|");
            char name[128];
            snprintf(name, sizeof name, "%.*s", (int)len, c);
            printf("%s", c == o->band_names ? "" : ", ");
            json_string(name);
            c += len + (c[len] == '|');
        }
        printf("], \"optional\": %s, \"kind\": \"raster\", \"output\": true}",
               o->optional ? "true" : "false");
    }
    printf("\n]");
}

/* The commands whose output is a vector file, which the library's registry
 * (rasters) does not declare: their face for front ends, as a product's, with
 * the options that name vector files the command reads. */
static const struct vector_command {
    const char *command, *title, *group, *output, *format, *vector_input;
} vector_commands[] = {
    {"roofs", "Roofs (solar cadastre)", "Sun", "roofs", "GPKG", "buildings"},
};

static void print_json_vector_command(const char *command)
{
    for (size_t i = 0; i < sizeof vector_commands / sizeof *vector_commands; ++i) {
        const struct vector_command *v = &vector_commands[i];
        if (strcmp(v->command, command) != 0)
            continue;
        printf(", \"title\": ");
        json_string(v->title);
        printf(", \"group\": ");
        json_string(v->group);
        printf(", \"outputs\": [\n  {\"name\": ");
        json_string(v->output);
        printf(", \"format\": ");
        json_string(v->format);
        printf(", \"optional\": false, \"kind\": \"vector\", \"output\": true}\n]");
        printf(", \"vector_inputs\": [");
        json_string(v->vector_input);
        printf("]");
    }
}

void opt_print_json(const opt_spec *const *tables, const char *command, const char *usage,
                    const char *summary, const char *version)
{
    static const char *const type_names[] = {"int", "double", "string", "choice", "flag", "list",
                                             "string", "string"};
    printf("{\"command\": ");
    json_string(command);
    printf(", \"version\": ");
    json_string(version);
    printf(", \"usage\": ");
    json_string(usage);
    printf(", \"summary\": ");
    json_string(summary);
    printf(", \"options\": [");
    const char *sep = "";
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s) {
            printf("%s\n  {\"name\": ", sep);
            json_string(s->name);
            printf(", \"dash\": ");
            json_string(opt_dash(s->name));
            printf(", \"type\": \"%s\"", type_names[s->type]);
            /* A file the command reads or writes, as the option table declares
             * it: front ends tell outputs from inputs by these flags. */
            if (s->type == OPT_INPUT)
                printf(", \"input\": true");
            if (s->type == OPT_OUTPUT)
                printf(", \"output\": true");
            if (s->metavar) {
                printf(", \"metavar\": ");
                json_string(s->metavar);
            }
            if (s->default_text && s->type != OPT_FLAG) {
                printf(", \"default\": ");
                json_string(s->default_text);
            }
            if (s->type == OPT_INT || s->type == OPT_DOUBLE) {
                printf(", \"min\": ");
                json_number(s->min);
                printf(", \"max\": ");
                json_number(s->max);
            }
            if (s->type == OPT_CHOICE) {
                printf(", \"choices\": [");
                for (const char *c = s->choices; *c;) {
                    size_t len = strcspn(c, "|");
                    char choice[64];
                    snprintf(choice, sizeof choice, "%.*s", (int)len, c);
                    json_string(choice);
                    c += len;
                    if (*c == '|' && *++c)
                        printf(", ");
                }
                printf("]");
            }
            printf(", \"group\": \"%s\"", opt_advanced(s->name) ? "advanced" : "basic");
            printf(", \"help\": ");
            json_string(s->help);
            printf("}");
            sep = ",";
        }
    printf("\n]");
    print_json_product(ss_product_named(command));
    print_json_vector_command(command);
    printf("}\n");
}

int opt_print_reference(const opt_spec *const *tables, int argc, char **argv, const char *command,
                        const char *usage, const char *summary, const char *version)
{
    if (argc != 2)
        return 0;
    if (strcmp(argv[1], "--help-markdown") == 0)
        opt_print_markdown(tables, command, usage, summary);
    else if (strcmp(argv[1], "--help-man") == 0)
        opt_print_man(tables, command, usage, summary, version);
    else if (strcmp(argv[1], "--help-completion") == 0)
        opt_print_completion(tables);
    else if (strcmp(argv[1], "--help-json") == 0)
        opt_print_json(tables, command, usage, summary, version);
    else
        return 0;
    return 1;
}
