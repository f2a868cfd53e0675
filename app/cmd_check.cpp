// `magbrush check CASE [--set key=value ...]`: validate a case and print it resolved, with
// units, and the numbers a designer derives from it. `--explain [--markdown]` prints the
// schema instead (docs/case_reference.md is `magbrush check --explain --markdown`).
// Exit codes: 0 valid, 1 invalid case, 2 usage error.
#include "subcommand.h"

#include "case_format.h"
#include "case_hash.h"
#include "case_parser.h"

#include <iostream>

namespace {

const char *usage =
    "Usage: magbrush check CASE.yaml [--set key=value ...] [--quiet | --inputs magnetic|electric]\n"
    "       magbrush check --explain [--markdown]\n\n"
    "Validates a case file (units, keys, ranges, geometry) and prints the resolved case with\n"
    "units, derived numbers (surface speeds, relative nip speed, particle counts and masses,\n"
    "pole field estimate) and the hashes of the magnetic and electric field inputs.\n\n"
    "  --set key=value  override a key, e.g. --set drum.gap=0.3mm --set roller.poles.N1.angle=95deg\n"
    "                   (list elements by name or [index]); validated like the file\n"
    "  --quiet          print nothing when the case is valid\n"
    "  --inputs KIND    print only the inputs the stored KIND field depends on (magnetic, electric),\n"
    "                   i.e. what its hash covers\n"
    "  --explain        print every key of the case schema: type, default, range, meaning\n"
    "  --markdown       with --explain: Markdown table (docs/case_reference.md)\n\n"
    "Exit status: 0 valid, 1 invalid case (errors on stderr), 2 usage error.\n";

int usage_error(const std::string &message)
{
  std::cerr << "magbrush check: " << message << "\n\n" << usage;
  return 2;
}

int run_check(const std::vector<std::string> &args)
{
  std::string case_file;
  std::vector<std::string> overrides;
  bool explain = false, markdown = false, quiet = false;
  std::string inputs;
  for (size_t i = 1; i < args.size(); ++i)
  {
    const std::string &a = args[i];
    if (a == "--help" || a == "-h")
    {
      std::cout << usage;
      return 0;
    }
    if (a == "--explain")
      explain = true;
    else if (a == "--markdown")
      markdown = true;
    else if (a == "--quiet" || a == "-q")
      quiet = true;
    else if (a == "--inputs")
    {
      if (i + 1 >= args.size() || (args[i + 1] != "magnetic" && args[i + 1] != "electric"))
        return usage_error("--inputs needs 'magnetic' or 'electric'");
      inputs = args[++i];
    }
    else if (a == "--set" || a == "-s")
    {
      if (i + 1 >= args.size())
        return usage_error("--set needs key=value (e.g. --set drum.gap=0.3mm)");
      overrides.push_back(args[++i]);
    }
    else if (a.rfind("--set=", 0) == 0)
      overrides.push_back(a.substr(6));
    else if (!a.empty() && a[0] == '-')
      return usage_error("unknown option '" + a + "'");
    else if (case_file.empty())
      case_file = a;
    else
      return usage_error("more than one case file given ('" + case_file + "' and '" + a + "')");
  }
  if (explain)
  {
    std::cout << magbrush::format_schema(markdown);
    return 0;
  }
  if (markdown)
    return usage_error("--markdown goes with --explain");
  if (case_file.empty())
    return usage_error("no case file given");
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
              << magbrush::format_derived(c) << "\n# field input hashes\n"
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

const bool registered = magbrush::register_subcommand(
    {"check", "validate a case and print it with units (--explain: the case-file reference)", run_check, 10});

} // namespace
