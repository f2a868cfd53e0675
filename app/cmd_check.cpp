// `magbrush check CASE [--set key=value ...]`: validate a case and print it resolved, with
// units, and the numbers a designer derives from it. `--explain [--markdown]` prints the
// schema instead (docs/case_reference.md is `magbrush check --explain --markdown`).
// Exit codes: 0 valid, 1 invalid case, 2 usage error.
#include "app/subcommand.h"

#include "case/case_format.h"
#include "case/case_hash.h"
#include "case/case_parser.h"
#include "fields/pole_field_summary.h"

#include <iostream>

namespace {

// The options, declared once: the parser and `magbrush run` read them (common/command_line.h).
const magbrush::cli::CommandSpec &check_command_line()
{
  static const magbrush::cli::CommandSpec spec = [] {
    magbrush::cli::CommandSpec s;
    s.program = "magbrush check";
    s.usage = "magbrush check CASE.yaml [--set key=value ...] [--quiet | --inputs magnetic|electric]\n"
              "       magbrush check --explain [--markdown]";
    s.description =
        "Validates a case file (units, keys, ranges, geometry) and prints the resolved case with\n"
        "units, derived numbers (surface speeds, relative nip speed, particle counts and masses,\n"
        "pole field estimate) and the hashes of the magnetic and electric field inputs.\n";
    s.positionals = {{"CASE.yaml", "the case file (not with --explain)", magbrush::cli::Positional::optional}};
    s.options = {
        {"--set", {"-s"}, "key=value",
         "override a key, e.g. --set drum.gap=0.3mm --set roller.poles.N1.angle=95deg\n"
         "(list elements by name or [index]); validated like the file",
         /*repeatable=*/true},
        {"--quiet", {"-q"}, "", "print nothing when the case is valid"},
        {"--inputs", {}, "KIND",
         "print only the inputs the stored KIND field depends on (magnetic, electric),\ni.e. what its hash covers",
         false, {"magnetic", "electric"}, /*for_pipeline=*/false},
        {"--explain", {}, "", "print every key of the case schema: type, default, range, meaning",
         false, {}, /*for_pipeline=*/false},
        {"--markdown", {}, "", "with --explain: Markdown table (docs/case_reference.md)", false, {}, false}};
    s.examples = {{"magbrush check cases/kawamoto_nip_fed.yaml", "validate the case and print it resolved, with units"},
                  {"magbrush check cases/kawamoto_nip_fed.yaml --set drum.gap=0.5mm --quiet",
                   "validate a variant; print only errors"},
                  {"magbrush check --explain", "every key of a case file: type, default, range, meaning"}};
    s.exit_status = "0 valid, 1 invalid case (errors on stderr), 2 usage error.";
    return s;
  }();
  return spec;
}

int check(const magbrush::cli::ParsedArguments &args)
{
  using magbrush::cli::UsageError;
  const std::string case_file = args.positional(0);
  const std::vector<std::string> overrides = args.values("--set");
  const bool explain = args.has("--explain"), markdown = args.has("--markdown"), quiet = args.has("--quiet");
  const std::string inputs = args.value("--inputs");
  if (explain)
  {
    std::cout << magbrush::format_schema(markdown);
    return 0;
  }
  if (markdown)
    throw UsageError("--markdown goes with --explain");
  if (case_file.empty())
    throw UsageError("no case file given");
  try
  {
    const magbrush::Case c = magbrush::load_case(case_file, overrides);
    if (quiet)
      return 0;
    if (!inputs.empty())
    {
      const auto kind = inputs == "magnetic" ? magbrush::FieldKind::magnetic : magbrush::FieldKind::electric;
      for (const auto &[key, value] : magbrush::field_inputs(c, kind))
        std::cout << key << " = " << value << "\n";
      std::cout << "# hash " << magbrush::field_hash(c, kind) << "\n";
      return 0;
    }
    std::cout << "# " << c.source_file << ": valid\n# resolved case (every key, defaults filled in):\n"
              << magbrush::format_case(c) << "\n# derived\n"
              << magbrush::format_derived(c) << magbrush::format_pole_field(c) << "\n# field input hashes\n"
              << "magnetic field  " << magbrush::field_hash(c, magbrush::FieldKind::magnetic) << "\n"
              << "electric field  " << magbrush::field_hash(c, magbrush::FieldKind::electric) << "\n";
    return 0;
  }
  catch (const magbrush::CaseError &e)
  {
    std::cerr << "magbrush check: " << e.what() << "\n";
    return 1;
  }
}

int run_check(const std::vector<std::string> &args)
{
  return magbrush::cli::run_command(check_command_line(), {args.begin() + 1, args.end()}, check);
}

const bool registered = magbrush::register_subcommand(
    {"check", "validate a case and print it with units (--explain: the case-file reference)", run_check,
     check_command_line, 10});

} // namespace
