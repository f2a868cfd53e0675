// The parser of command_line.h: declarations in, parsed arguments (or one clear message) out.
#include "common/command_line.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace magbrush::cli {

// ---------------------------------------------------------------------------------------
// Declarations

bool Option::is_called(const std::string &spelling) const
{
  return spelling == name || std::find(aliases.begin(), aliases.end(), spelling) != aliases.end();
}

const Option *CommandSpec::find(const std::string &spelling) const
{
  for (const Option &o : options)
    if (o.is_called(spelling))
      return &o;
  return nullptr;
}

Option set_option(const std::string &example)
{
  return {"--set", {"-s"}, "key=value",
          "override a case key, validated like the file (repeatable),\ne.g. --set " + example,
          /*repeatable=*/true};
}

// ---------------------------------------------------------------------------------------
// Did you mean: the optimal-string-alignment distance (edits, counting a swap of two
// neighbouring characters as one edit, the commonest typo).

namespace {

std::size_t edit_distance(const std::string &a, const std::string &b)
{
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i)
    d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j)
    d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j)
    {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

} // namespace

std::string closest_option(const CommandSpec &spec, const std::string &word)
{
  // A third of the word may be wrong, but at least one character: "-np" is not a typo of "-s".
  const std::size_t tolerance = std::max<std::size_t>(1, word.size() / 3);
  std::string best;
  std::size_t best_distance = tolerance + 1;
  auto consider = [&](const std::string &spelling) {
    const std::size_t d = edit_distance(word, spelling);
    if (d < best_distance)
    {
      best = spelling;
      best_distance = d;
    }
  };
  for (const Option &o : spec.options)
  {
    consider(o.name);
    for (const auto &a : o.aliases)
      consider(a);
  }
  consider("--help");
  return best;
}

// ---------------------------------------------------------------------------------------
// Parsing

namespace {
bool is_help(const std::string &word) { return word == "--help" || word == "-h"; }

// "-x", "--xyz": an option word. A lone "-" is a positional (it often means stdin).
bool looks_like_option(const std::string &word) { return word.size() > 1 && word[0] == '-'; }

std::string join(const std::vector<std::string> &words, const std::string &separator)
{
  std::string out;
  for (const auto &w : words)
    out += (out.empty() ? "" : separator) + w;
  return out;
}
// "a, b or c"
std::string one_of(const std::vector<std::string> &choices)
{
  if (choices.size() < 2)
    return join(choices, "");
  return join({choices.begin(), choices.end() - 1}, ", ") + " or " + choices.back();
}
} // namespace

// Walks the words once. The first mistake is remembered rather than thrown at once, so that
// `--help` anywhere still prints the help (a user asking for help gets it).
class Parser
{
public:
  Parser(const CommandSpec &spec, const std::vector<std::string> &args) : spec_(spec), args_(args) {}

  ParsedArguments run()
  {
    bool only_positionals = false;
    for (next_ = 0; next_ < args_.size();)
    {
      const std::string word = args_[next_++];
      if (only_positionals || !looks_like_option(word))
        take_positional(word);
      else if (word == "--")
        only_positionals = true;
      else if (is_help(word))
        result_.help_requested_ = true;
      else
        take_option(word);
    }
    if (result_.help_requested_)
      return result_;
    check_required_positionals();
    if (!first_error_.empty())
      throw UsageError(first_error_);
    return result_;
  }

private:
  const CommandSpec &spec_;
  const std::vector<std::string> &args_;
  std::size_t next_ = 0;
  ParsedArguments result_;
  std::string first_error_;

  void fail(const std::string &message)
  {
    if (first_error_.empty())
      first_error_ = message;
  }

  // "--opt", "--opt=value", "--opt value".
  void take_option(const std::string &word)
  {
    const std::size_t equals = word.rfind("--", 0) == 0 ? word.find('=') : std::string::npos;
    const std::string spelling = word.substr(0, equals);
    const Option *option = spec_.find(spelling);
    if (!option)
    {
      const std::string suggestion = closest_option(spec_, spelling);
      fail("unknown option '" + spelling + "'" +
           (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)"));
      return;
    }
    if (!option->takes_value())
    {
      if (equals != std::string::npos)
        fail(option->name + " takes no value (found '" + word + "')");
      result_.given_.push_back({option, ""});
      return;
    }
    std::string value;
    if (equals != std::string::npos)
      value = word.substr(equals + 1);
    else if (next_ < args_.size())
      value = args_[next_++];
    else
    {
      fail(spelling + " needs a value: " + spelling + " " + option->value_name);
      return;
    }
    if (!option->choices.empty() &&
        std::find(option->choices.begin(), option->choices.end(), value) == option->choices.end())
    {
      fail(spelling + " expects " + one_of(option->choices) + ", found '" + value + "'");
      return;
    }
    result_.given_.push_back({option, value});
  }

  void take_positional(const std::string &word)
  {
    const std::size_t index = result_.positionals_.size();
    if (index >= spec_.positionals.size() && !spec_.positionals.empty() &&
        spec_.positionals.back().need == Positional::one_or_more)
    {
      result_.positionals_.push_back(word);
      return;
    }
    if (index >= spec_.positionals.size())
    {
      if (spec_.positionals.empty())
        fail("unexpected argument '" + word + "'");
      else
        fail("unexpected argument '" + word + "' (" + spec_.positionals.back().name + " is already '" +
             result_.positionals_.back() + "')");
      return;
    }
    result_.positionals_.push_back(word);
  }

  void check_required_positionals()
  {
    for (std::size_t k = result_.positionals_.size(); k < spec_.positionals.size(); ++k)
      if (spec_.positionals[k].need != Positional::optional)
      {
        const Positional &p = spec_.positionals[k];
        fail("missing " + p.name + (p.help.empty() ? "" : " (" + p.help + ")"));
        return;
      }
  }
};

ParsedArguments parse(const CommandSpec &spec, const std::vector<std::string> &args)
{
  return Parser(spec, args).run();
}

// ---------------------------------------------------------------------------------------
// Reading what was parsed

bool ParsedArguments::has(const std::string &name) const
{
  for (const Given &g : given_)
    if (g.option->is_called(name))
      return true;
  return false;
}

std::string ParsedArguments::value(const std::string &name, const std::string &fallback) const
{
  std::string found = fallback;
  for (const Given &g : given_)
    if (g.option->is_called(name))
      found = g.value; // the last one given counts
  return found;
}

std::vector<std::string> ParsedArguments::values(const std::string &name) const
{
  std::vector<std::string> found;
  for (const Given &g : given_)
    if (g.option->is_called(name))
      found.push_back(g.value);
  return found;
}

long ParsedArguments::whole_number(const std::string &name, long fallback, long min, long max) const
{
  if (!has(name))
    return fallback;
  const std::string text = value(name);
  char *end = nullptr;
  errno = 0;
  const long number = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || number < min || number > max)
    throw UsageError(name + " expects a whole number in " + std::to_string(min) + ".." +
                     std::to_string(max) + ", found '" + text + "'");
  return number;
}

std::string ParsedArguments::positional(std::size_t index) const
{
  return index < positionals_.size() ? positionals_[index] : std::string();
}

// ---------------------------------------------------------------------------------------
// Help and errors

namespace {

// "-o, --output DIR": short spellings first, then the long name, then other long ones.
std::string spellings_of(const Option &o)
{
  std::vector<std::string> names;
  for (const auto &a : o.aliases)
    if (a.rfind("--", 0) != 0)
      names.push_back(a);
  names.push_back(o.name);
  for (const auto &a : o.aliases)
    if (a.rfind("--", 0) == 0)
      names.push_back(a);
  return join(names, ", ") + (o.takes_value() ? " " + o.value_name : "");
}

// Two columns: the names, then the help, whose further lines are indented to its column.
void write_two_columns(std::ostream &out, const std::vector<std::pair<std::string, std::string>> &rows)
{
  std::size_t width = 0;
  for (const auto &[left, right] : rows)
    width = std::max(width, left.size());
  width = std::min<std::size_t>(width, 28);
  for (const auto &[left, right] : rows)
  {
    out << "  " << left;
    std::istringstream lines(right);
    std::string line;
    bool first = true;
    while (std::getline(lines, line))
    {
      if (first && left.size() <= width)
        out << std::string(width - left.size() + 2, ' ') << line << "\n";
      else if (first)
        out << "\n" << std::string(width + 4, ' ') << line << "\n";
      else
        out << std::string(width + 4, ' ') << line << "\n";
      first = false;
    }
    if (first)
      out << "\n";
  }
}

std::string usage_block(const CommandSpec &spec) { return "Usage: " + spec.usage + "\n"; }

} // namespace

std::string help_text(const CommandSpec &spec)
{
  std::ostringstream out;
  out << usage_block(spec);
  if (!spec.description.empty())
    out << "\n" << spec.description;
  std::vector<std::pair<std::string, std::string>> arguments;
  for (const Positional &p : spec.positionals)
    if (!p.help.empty())
      arguments.emplace_back(p.name, p.help + (p.need == Positional::optional      ? " (optional)"
                                               : p.need == Positional::one_or_more ? " (one or more)"
                                                                                   : ""));
  if (!arguments.empty())
  {
    out << "\nArguments:\n";
    write_two_columns(out, arguments);
  }
  std::vector<std::pair<std::string, std::string>> options;
  for (const Option &o : spec.options)
    options.emplace_back(spellings_of(o), o.help);
  options.emplace_back("-h, --help", "print this help");
  out << "\nOptions:\n";
  write_two_columns(out, options);
  if (!spec.epilog.empty())
    out << "\n" << spec.epilog;
  if (!spec.examples.empty())
  {
    out << "\nExample" << (spec.examples.size() > 1 ? "s" : "") << ":\n";
    for (const auto &e : spec.examples)
      out << "  " << e.command << "\n" << (e.what.empty() ? "" : "      " + e.what + "\n");
  }
  if (!spec.exit_status.empty())
    out << "\nExit status: " << spec.exit_status << "\n";
  return out.str();
}

std::string usage_error_text(const CommandSpec &spec, const std::string &message)
{
  return spec.program + ": " + message + "\n\n" + usage_block(spec) + "(" + spec.program +
         " --help for details)\n";
}

int run_command(const CommandSpec &spec, const std::vector<std::string> &args,
                const std::function<int(const ParsedArguments &)> &body)
{
  try
  {
    const ParsedArguments arguments = parse(spec, args);
    if (arguments.help_requested())
    {
      std::cout << help_text(spec);
      return 0;
    }
    return body(arguments);
  }
  catch (const UsageError &e)
  {
    std::cerr << usage_error_text(spec, e.what());
    return 2;
  }
}

std::vector<std::string> forward_options(const ParsedArguments &arguments, const CommandSpec &stage, Forward which)
{
  std::vector<std::string> words;
  for (const auto &given : arguments.given())
  {
    const Option *theirs = stage.find(given.option->name);
    if (!theirs || (which == Forward::pipeline_options && !theirs->for_pipeline))
      continue;
    words.push_back(theirs->name);
    if (theirs->takes_value())
      words.push_back(given.value);
  }
  return words;
}

} // namespace magbrush::cli
