// One command-line parser for every magbrush program and subcommand.
//
// A command declares what it accepts once, as data — a CommandSpec:
//
//   CommandSpec spec;
//   spec.program = "magbrush mesh";
//   spec.usage = "magbrush mesh CASE.yaml [--set key=value ...] [-o DIR]";
//   spec.positionals = {{"CASE", "the case file", Positional::required}};
//   spec.options = {set_option(), {"--output", {"-o"}, "DIR", "where to write"}};
//
// and the parser does the rest the same way everywhere:
//
//   --opt value, --opt=value, -o value       an option with a value
//   --set key=value, -s key=value, --set=k=v a repeatable option: every value, in order
//   --flag                                   an option without a value
//   --help, -h                               the help generated from the declaration
//   --                                       everything after it is positional
//
// Mistakes are reported in one style, on stderr, followed by the usage, with exit code 2:
//
//   magbrush mesh: unknown option '--outptu' (did you mean '--output'?)
//
// Because the declaration is data, other code can read it: `magbrush run` asks each stage
// which options it declares and hands it only those (see forward_options()).
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace magbrush::cli {

// One option: its long name (with the dashes, "--output"), other spellings ("-o"), the name
// of its value in the help ("DIR"; empty for a flag without a value), a help text (its first
// line goes next to the name; further lines are indented below it), and whether it may be
// given more than once (every value is kept, in order) or not (the last one given counts).
struct Option
{
  std::string name;
  std::vector<std::string> aliases = {};
  std::string value_name = {};
  std::string help = {};
  bool repeatable = false;
  // When not empty: the only values accepted ("magnetic", "electric").
  std::vector<std::string> choices = {};
  // Whether `magbrush run` and `magbrush sweep` may pass it on to this stage. An option
  // that names one stage's own output (-o) or narrows it (--only) is not for the pipeline.
  bool for_pipeline = true;

  bool takes_value() const { return !value_name.empty(); }
  bool is_called(const std::string &spelling) const;
};

// A word that is not an option: the case file, usually.
struct Positional
{
  // one_or_more: required, and it takes every further word too (only the last positional).
  enum Need { required, optional, one_or_more };
  std::string name; // "CASE"
  std::string help = {};
  Need need = required;
};

// Everything a command accepts, and the text around the generated option list.
struct CommandSpec
{
  std::string program;       // "magbrush mesh", "magbrush-dem": starts every message
  std::string usage;         // the synopsis line(s), without "Usage: "
  std::string description;   // paragraphs between the usage and the options
  std::vector<Positional> positionals;
  std::vector<Option> options;
  std::string epilog;        // after the options: notes
  // Every magbrush command ends its help the same way: its examples (a command line and what
  // it does), then its exit status.
  struct Example
  {
    std::string command; // "magbrush run cases/kawamoto_nip_fed.yaml --quick"
    std::string what;    // "a first look in about a minute"
  };
  std::vector<Example> examples;
  std::string exit_status;   // "0 done, 1 ..., 2 bad usage"

  const Option *find(const std::string &spelling) const;
};

// The option every magbrush command shares: --set key=value (alias -s), repeatable.
Option set_option(const std::string &example = "drum.gap=0.3mm");

// A mistake on the command line. The message names what is wrong; the caller adds the
// program name and the usage (usage_error_text()).
class UsageError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// What was given, in the order it was given. It points into the CommandSpec it was parsed
// with, so that spec must outlive it (every command keeps its spec in a function's static).
class ParsedArguments
{
public:
  struct Given
  {
    const Option *option;
    std::string value; // empty for a flag
  };

  bool help_requested() const { return help_requested_; }
  // Was the option (any spelling) given?
  bool has(const std::string &name) const;
  // The value of a single-valued option, or `fallback` when it was not given.
  std::string value(const std::string &name, const std::string &fallback = "") const;
  // Every value of a repeatable option, in the order given.
  std::vector<std::string> values(const std::string &name) const;
  // A whole number in [min, max]; a UsageError naming the option otherwise.
  long whole_number(const std::string &name, long fallback, long min, long max) const;

  const std::vector<std::string> &positionals() const { return positionals_; }
  // The positional at `index`, or "" when there are fewer.
  std::string positional(std::size_t index) const;
  const std::vector<Given> &given() const { return given_; }

private:
  friend class Parser;
  bool help_requested_ = false;
  std::vector<Given> given_;
  std::vector<std::string> positionals_;
};

// Parses `args` (the words after the program or subcommand name) against `spec`. Throws
// UsageError on the first mistake, unless --help was asked for anywhere (then the help wins).
ParsedArguments parse(const CommandSpec &spec, const std::vector<std::string> &args);

// The generated help: usage, description, positionals, options, epilog.
std::string help_text(const CommandSpec &spec);

// "<program>: <message>\n\nUsage: ...\n(<program> --help for details)\n"
std::string usage_error_text(const CommandSpec &spec, const std::string &message);

// Runs a command the usual way: parses, prints the help on --help (exit 0), prints a usage
// error on a mistake (exit 2) — also one that `body` throws as UsageError after its own
// checks — and otherwise returns what `body` returns.
int run_command(const CommandSpec &spec, const std::vector<std::string> &args,
                const std::function<int(const ParsedArguments &)> &body);

// The options in `arguments` that `stage` declares, written back as words ("--set",
// "drum.gap=0.3mm", "--force"), in the order given. With Forward::pipeline_options (how
// `magbrush run` hands each stage only what it understands) the stage's options marked
// for_pipeline = false are left out; with Forward::every_option (a wrapper handing its own
// arguments to the program behind it) none is.
enum class Forward
{
  pipeline_options,
  every_option
};
std::vector<std::string> forward_options(const ParsedArguments &arguments, const CommandSpec &stage,
                                         Forward which = Forward::pipeline_options);

// The spelling closest to `word` among the options of `spec`, or "" when none is close
// enough to be a likely typo.
std::string closest_option(const CommandSpec &spec, const std::string &word);

} // namespace magbrush::cli
