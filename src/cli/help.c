/* The help texts, made from the command registry, the option tables (cli.h) and the deck schemas, every
 * line at most CLI_WIDTH columns wide: long lines wrap with a hanging indent. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "mica/text.h"

static const char *const conventions =
    "Long options take their value after a space or '=' (--output DIR, --output=DIR) and may be shortened "
    "while unambiguous (--out); a short option's value may follow it at once (-oDIR). Options and the deck "
    "come in any order; '--' ends the options, so that what follows is the deck even if its name starts "
    "with '-': mica run -- -odd.cfg.";

static const char *const exit_status =
    "exit status: 0 success, 2 bad input (deck or command line), 3 numerical failure, 1 other errors";

static void paragraph(const char *text, FILE *out) { mica_text_wrap(out, text, 0, 0, CLI_WIDTH, NULL); }

static void print_commands(FILE *out) {
  int column = 0;
  const MicaCommand *c;
  for (int i = 0; (c = mica_command_at(i)); i++) {
    int width = mica_text_width(c->type.name, strlen(c->type.name)) + 5;
    if (width > column) column = width;
  }
  for (int i = 0; (c = mica_command_at(i)); i++) {
    fputs("  ", out);
    mica_text_pad(out, c->type.name, column - 2);
    mica_text_wrap(out, c->type.description, column, column, CLI_WIDTH, NULL);
  }
}

void cli_print_program_help(FILE *out) {
  fputs("mica " MICA_VERSION " — meshfree MLS/EFG solver for solids and generalized continua\n\n", out);
  fputs("usage: mica <command>", out);
  cli_print_option_synopsis(cli_command_options, out);
  fputs(" [--] DECK\n"
        "       mica help [<command>]      the command's options and deck settings (= mica <command> --help)\n"
        "       mica help --markdown [--group GROUP] <command>\n"
        "                                  its deck settings as a Markdown table (docs/input.md's)\n"
        "       mica --help | --version\n\n"
        "commands:\n",
        out);
  print_commands(out);
  fputs("\noptions of every command:\n", out);
  cli_print_options(cli_command_options, out);
  fputs("\noptions of mica itself (before the command):\n", out);
  cli_print_options(cli_program_options, out);
  fputs("\noptions of mica help:\n", out);
  cli_print_options(cli_help_options, out);
  fputs("\nexamples:\n"
        "  mica run input/cantilever.cfg                    # results in out/cantilever/\n"
        "  mica mls input/mls_skatulla.cfg -o out/order3 --set mls.order=3 --set mls.radius=3.01\n"
        "  mica mls input/mls_quickstart.cfg --set \"particles.count=[41,41]\" --set 'function.f=\"x^2\"'\n"
        "  mica run input/cantilever.cfg --set parameters.L=20 --output=out/long\n\n",
        out);
  paragraph(conventions, out);
  fputc('\n', out);
  paragraph(exit_status, out);
  fputs("documentation: README.md, docs/input.md\n", out);
}

void cli_print_command_usage(const MicaCommand *command, FILE *out) {
  fprintf(out, "usage: mica %s", command->type.name);
  cli_print_option_synopsis(cli_command_options, out);
  fputs(" [--] DECK\n", out);
}

int cli_print_command_help(const MicaCommand *command, FILE *out) {
  cli_print_command_usage(command, out);
  fprintf(out, "       mica %s --help   (the same as mica help %s)\n\n", command->type.name, command->type.name);
  paragraph(command->type.description, out);
  fputc('\n', out);
  paragraph(command->text, out);
  fputs("\noptions:\n", out);
  cli_print_options(cli_command_options, out);
  fputc('\n', out);
  paragraph(conventions, out);
  fputc('\n', out);
  paragraph(exit_status, out);
  fputs("\nsettings of the deck (docs/input.md):\n", out);
  return mica_deck_print_schema(command->schema, CLI_WIDTH, out);
}

int cli_print_command_markdown(const MicaCommand *command, const char *group, FILE *out) {
  return mica_deck_print_schema_markdown(command->schema, group, out);
}
