// The parser of common/command_line.h: every accepted form, every error and its wording,
// the did-you-mean suggestion, the order of a repeatable option, the generated help, and the
// forwarding of options to the stages that declare them.
#include "common/command_line.h"

#include <gtest/gtest.h>

#include <iostream>
#include <sstream>

namespace {

using namespace magbrush::cli;

// A command with one of each kind: a repeatable option with a short alias, options with a
// value, a flag, an option with fixed choices, a stage-local option, and one positional.
const CommandSpec &example()
{
  static const CommandSpec spec = [] {
    CommandSpec s;
    s.program = "magbrush example";
    s.usage = "magbrush example CASE [--set key=value ...] [-o DIR]";
    s.description = "An example command.\n";
    s.positionals = {{"CASE", "the case file"}};
    s.options = {set_option(),
                 {"--output", {"-o"}, "DIR", "where to write"},
                 {"--threads", {}, "N", "how many threads\nsecond line of help"},
                 {"--force", {}, "", "recompute"},
                 {"--only", {}, "WHICH", "one of them", false, {"magnetic", "electric"}, false},
                 {"--np", {"-np"}, "N", "processes"}};
    s.epilog = "Exit status: 0 done.\n";
    return s;
  }();
  return spec;
}

ParsedArguments parse_words(const std::vector<std::string> &words) { return parse(example(), words); }

std::string error_of(const std::vector<std::string> &words)
{
  try
  {
    parse_words(words);
  }
  catch (const UsageError &e)
  {
    return e.what();
  }
  return "(no error)";
}

TEST(CommandLine, ValueFormsAreEquivalent)
{
  for (const auto &words : std::vector<std::vector<std::string>>{
           {"case.yaml", "--output", "out dir"}, {"case.yaml", "--output=out dir"}, {"case.yaml", "-o", "out dir"}})
  {
    const ParsedArguments a = parse_words(words);
    EXPECT_EQ(a.value("--output"), "out dir");
    EXPECT_EQ(a.value("-o"), "out dir"); // any spelling reads it
    EXPECT_EQ(a.positional(0), "case.yaml");
  }
}

TEST(CommandLine, SetIsRepeatableInOrderInEveryForm)
{
  const ParsedArguments a = parse_words(
      {"--set", "a=1", "case.yaml", "-s", "b=2", "--set=c=3", "--set", "a=4"});
  EXPECT_EQ(a.values("--set"), (std::vector<std::string>{"a=1", "b=2", "c=3", "a=4"}));
  EXPECT_EQ(a.positionals(), std::vector<std::string>{"case.yaml"});
}

TEST(CommandLine, FlagsChoicesAndDefaults)
{
  const ParsedArguments a = parse_words({"case.yaml", "--force", "--only", "electric"});
  EXPECT_TRUE(a.has("--force"));
  EXPECT_EQ(a.value("--only"), "electric");
  EXPECT_FALSE(a.has("--threads"));
  EXPECT_EQ(a.value("--threads", "4"), "4");
  EXPECT_EQ(a.whole_number("--threads", 7, 1, 64), 7);
}

TEST(CommandLine, ASingleValuedOptionGivenTwiceKeepsTheLast)
{
  EXPECT_EQ(parse_words({"c", "-o", "a", "--output", "b"}).value("--output"), "b");
}

TEST(CommandLine, ValuesMayStartWithADash)
{
  EXPECT_EQ(parse_words({"c", "--set", "-x=1"}).values("--set"), std::vector<std::string>{"-x=1"});
}

TEST(CommandLine, DoubleDashEndsTheOptions)
{
  EXPECT_EQ(parse_words({"--", "--odd-name.yaml"}).positional(0), "--odd-name.yaml");
}

TEST(CommandLine, WholeNumbersAreChecked)
{
  EXPECT_EQ(parse_words({"c", "--threads", "12"}).whole_number("--threads", 1, 1, 64), 12);
  try
  {
    parse_words({"c", "--threads", "twelve"}).whole_number("--threads", 1, 1, 64);
    FAIL() << "no error";
  }
  catch (const UsageError &e)
  {
    EXPECT_EQ(std::string(e.what()), "--threads expects a whole number in 1..64, found 'twelve'");
  }
}

TEST(CommandLine, UnknownOptionSuggestsTheClosest)
{
  EXPECT_EQ(error_of({"c", "--outptu", "x"}), "unknown option '--outptu' (did you mean '--output'?)");
  EXPECT_EQ(error_of({"c", "--forse"}), "unknown option '--forse' (did you mean '--force'?)");
  EXPECT_EQ(error_of({"c", "--frobnicate"}), "unknown option '--frobnicate'");
  EXPECT_EQ(error_of({"c", "--outptu=x"}), "unknown option '--outptu' (did you mean '--output'?)");
}

TEST(CommandLine, OtherMistakes)
{
  EXPECT_EQ(error_of({"c", "--output"}), "--output needs a value: --output DIR");
  EXPECT_EQ(error_of({"c", "-s"}), "-s needs a value: -s key=value");
  EXPECT_EQ(error_of({"c", "--force=yes"}), "--force takes no value (found '--force=yes')");
  EXPECT_EQ(error_of({"c", "--only", "nip"}), "--only expects magnetic or electric, found 'nip'");
  EXPECT_EQ(error_of({"a.yaml", "b.yaml"}), "unexpected argument 'b.yaml' (CASE is already 'a.yaml')");
  EXPECT_EQ(error_of({"--force"}), "missing CASE (the case file)");
}

TEST(CommandLine, HelpWinsEvenAfterAMistake)
{
  EXPECT_TRUE(parse_words({"--help"}).help_requested());
  EXPECT_TRUE(parse_words({"-h"}).help_requested());
  EXPECT_TRUE(parse_words({"c", "--bogus", "--help"}).help_requested());
}

TEST(CommandLine, GeneratedHelp)
{
  const std::string help = help_text(example());
  EXPECT_EQ(help.rfind("Usage: magbrush example CASE", 0), 0u) << help;
  EXPECT_NE(help.find("An example command."), std::string::npos) << help;
  EXPECT_NE(help.find("  -s, --set key=value"), std::string::npos) << help;
  EXPECT_NE(help.find("  -o, --output DIR"), std::string::npos) << help;
  EXPECT_NE(help.find("  -np, --np N"), std::string::npos) << help;
  EXPECT_NE(help.find("  -h, --help"), std::string::npos) << help;
  // A second help line is indented under the first.
  const auto first = help.find("how many threads\n");
  ASSERT_NE(first, std::string::npos) << help;
  const auto second = help.find("second line of help", first);
  const auto column = first - help.rfind('\n', first) - 1;
  EXPECT_EQ(second - first - std::string("how many threads\n").size(), column) << help;
  EXPECT_NE(help.find("Exit status: 0 done."), std::string::npos) << help;
}

TEST(CommandLine, RunCommandExitCodesAndOneErrorStyle)
{
  auto body = [](const ParsedArguments &) { return 5; };
  std::ostringstream err;
  auto *old = std::cerr.rdbuf(err.rdbuf());
  const int bad = run_command(example(), {"c", "--outptu", "x"}, body);
  const int body_error = run_command(example(), {"c"}, [](const ParsedArguments &) -> int {
    throw UsageError("--markdown goes with --explain");
  });
  std::cerr.rdbuf(old);
  EXPECT_EQ(bad, 2);
  EXPECT_EQ(body_error, 2);
  EXPECT_NE(err.str().find("magbrush example: unknown option '--outptu' (did you mean '--output'?)\n\n"
                           "Usage: magbrush example CASE"),
            std::string::npos)
      << err.str();
  EXPECT_NE(err.str().find("magbrush example: --markdown goes with --explain"), std::string::npos) << err.str();
  EXPECT_EQ(run_command(example(), {"c"}, body), 5);
  std::ostringstream out;
  old = std::cout.rdbuf(out.rdbuf());
  const int help = run_command(example(), {"--help"}, body);
  std::cout.rdbuf(old);
  EXPECT_EQ(help, 0);
  EXPECT_EQ(out.str(), help_text(example()));
}

TEST(CommandLine, ForwardOnlyWhatTheStageDeclares)
{
  CommandSpec stage;
  stage.program = "stage";
  stage.options = {set_option(), {"--force", {}, "", "recompute"}, {"--output", {"-o"}, "DIR", "", false, {}, false}};
  const ParsedArguments a =
      parse_words({"c", "-s", "a=1", "--threads", "2", "--force", "-o", "d", "-np", "3", "--set=b=2"});
  EXPECT_EQ(forward_options(a, stage), (std::vector<std::string>{"--set", "a=1", "--force", "--set", "b=2"}));
}

} // namespace

TEST(CommandLine, ALastPositionalOfOneOrMoreTakesEveryFurtherWord)
{
  CommandSpec spec;
  spec.program = "magbrush compare";
  spec.usage = "magbrush compare RUN_A RUN_B [RUN ...]";
  spec.positionals = {{"RUN_A", "the reference"}, {"RUN_B", "the others", Positional::one_or_more}};
  const ParsedArguments three = parse(spec, {"a", "b", "c"});
  EXPECT_EQ(three.positionals(), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_THROW(parse(spec, {"a"}), UsageError); // one or more: RUN_B is required
  EXPECT_NE(help_text(spec).find("(one or more)"), std::string::npos);
}

TEST(CommandLine, TheHelpEndsWithTheExamplesThenTheExitStatus)
{
  CommandSpec spec;
  spec.program = "magbrush check";
  spec.usage = "magbrush check CASE";
  spec.epilog = "A note.\n";
  spec.examples = {{"magbrush check a.yaml", "validate it"}};
  spec.exit_status = "0 valid, 1 invalid, 2 bad usage.";
  const std::string help = help_text(spec);
  const auto note = help.find("A note."), example = help.find("Example:\n  magbrush check a.yaml\n      validate it\n"),
             exit_status = help.find("Exit status: 0 valid, 1 invalid, 2 bad usage.\n");
  ASSERT_NE(example, std::string::npos) << help;
  ASSERT_NE(exit_status, std::string::npos) << help;
  EXPECT_LT(note, example);
  EXPECT_LT(example, exit_status);
}
