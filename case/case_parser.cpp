// The case reader. Three passes, each collecting every error it can before stopping:
//   1. text checks and YAML parsing (a syntax error quotes its line with a caret and a hint;
//      an unclosed '{' or '[' is pointed at itself, not where yaml-cpp noticed it);
//   2. overrides are grafted onto the YAML tree, then a walk of the tree against the schema
//      (case_schema.h) checks keys, types, units and ranges and stores SI values by key path;
//   3. the Case struct is assembled from those values (schema defaults for the rest) and
//      checked for geometric sense (case_validation.h).
// The walk only descends where the schema has keys, so YAML alias cycles and absurd nesting
// are never followed.
#include "case/case_parser.h"
#include "case/case_format.h"
#include "case/run_folder.h"

#include "case/case_schema.h"
#include "case/case_validation.h"
#include "case/units.h"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace magbrush {

namespace {

constexpr double pi = 3.14159265358979323846;

// A checked leaf value, in SI.
struct Value
{
  const KeySpec *spec = nullptr;
  std::string written;          // as written (for messages)
  double number = 0.0;          // quantity
  long long integer = 0;
  bool flag = false;
  std::string text;             // string / choice
  std::vector<double> numbers;  // vector3, polygon (x0, y0, x1, ...), box (6)
};

// A place in the input: a file position or an override.
struct Origin
{
  std::string where; // "file:line:col" or "--set key=value"
};

std::string node_kind(const YAML::Node &n)
{
  switch (n.Type())
  {
  case YAML::NodeType::Null: return "nothing";
  case YAML::NodeType::Scalar:
    return n.Scalar().size() <= 80 ? "'" + n.Scalar() + "'"
                                   : "'" + n.Scalar().substr(0, 60) + "...' (" + std::to_string(n.Scalar().size()) +
                                         " characters)";
  case YAML::NodeType::Sequence: return "a list";
  case YAML::NodeType::Map: return "a section (key: value lines)";
  default: return "an undefined value";
  }
}

std::string join(const std::vector<std::string> &items, const std::string &sep)
{
  std::string s;
  for (size_t i = 0; i < items.size(); ++i)
    s += (i ? sep : "") + items[i];
  return s;
}

class CaseReader
{
public:
  CaseReader(std::string file_name, std::vector<std::string> overrides)
    : file(std::move(file_name)), overrides(std::move(overrides))
  {}

  Case read(const std::string &text)
  {
    check_text(text);
    throw_if_errors();
    YAML::Node root = parse_yaml(text);
    throw_if_errors();
    apply_overrides(root);
    walk_section(root, "", "", root);
    throw_if_errors();
    Case c = build();
    throw_if_errors();
    for (const auto &issue : validate_case(c))
      error_at_path(issue.path, issue.message);
    throw_if_errors();
    return c;
  }

private:
  std::string file;
  std::vector<std::string> overrides;
  std::vector<std::string> errors;
  std::map<std::string, std::string> override_origin; // display path -> "--set ..."
  std::map<std::string, std::string> override_path;   // "key=value" as given -> its display path
  std::map<std::string, std::string> locations;       // display path -> "file:l:c"
  std::map<std::string, Value> values;                // display path -> leaf value
  std::set<std::string> present;                      // display paths of given containers
  std::map<std::string, std::vector<std::string>> items; // list/map path -> item paths
  std::map<std::string, std::string> item_names;      // item path -> its name
  std::map<std::string, Value> defaults;              // pattern -> parsed schema default

  // ---- errors -------------------------------------------------------------------------
  std::string location(const YAML::Mark &mark) const
  {
    if (mark.line < 0)
      return file;
    return file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
  }

  // The override that produced this path (or one of its parents), if any.
  const std::string *override_for(const std::string &path) const
  {
    for (const auto &[p, text] : override_origin)
      if (path == p || path.rfind(p + ".", 0) == 0 || path.rfind(p + "[", 0) == 0)
        return &text;
    return nullptr;
  }

  void error(const std::string &where, const std::string &path, const std::string &message)
  {
    if (errors.size() < 50)
      errors.push_back(where + ": " + (path.empty() ? "" : path + ": ") + message);
  }

  void error_at(const YAML::Node &node, const std::string &path, const std::string &message)
  {
    if (const std::string *o = override_for(path))
      error(*o, path, message);
    else
      error(location(node.Mark()), path, message);
  }

  // Errors found after the walk: locate the key itself or its nearest given parent.
  void error_at_path(const std::string &path, const std::string &message)
  {
    if (const std::string *o = override_for(path))
      return error(*o, path, message);
    std::string p = path;
    while (!p.empty())
    {
      const auto it = locations.find(p);
      if (it != locations.end())
        return error(it->second, path, message);
      const auto cut = p.find_last_of(".[");
      p = (cut == std::string::npos) ? "" : p.substr(0, cut);
    }
    error(file, path, message);
  }

  void throw_if_errors()
  {
    if (errors.empty())
      return;
    std::string message = "invalid case '" + file + "' (" + std::to_string(errors.size()) +
                          (errors.size() == 1 ? " error" : " errors") + "):";
    for (const auto &e : errors)
      message += "\n  " + e;
    if (errors.size() >= 50)
      message += "\n  (stopped after 50 errors)";
    throw CaseError(message);
  }

  // ---- pass 1: text and YAML ------------------------------------------------------------
  void check_text(const std::string &text)
  {
    if (text.size() > max_case_file_bytes)
      return error(file, "", "the file has " + std::to_string(text.size()) +
                                 " bytes; case files are small YAML text files (limit " +
                                 std::to_string(max_case_file_bytes) + " bytes)");
    if (text.find('\0') != std::string::npos)
      return error(file, "", "this is not a text file (it contains NUL bytes); expected a YAML case file");
    // Invalid UTF-8 and tab indentation, reported with their position.
    int line = 1, column = 1;
    bool at_indent = true;
    for (size_t i = 0; i < text.size(); ++i)
    {
      const unsigned char c = static_cast<unsigned char>(text[i]);
      size_t extra = 0;
      if (c >= 0x80)
      {
        extra = (c >= 0xF0 && c < 0xF8) ? 3 : (c >= 0xE0) ? 2 : (c >= 0xC2 && c < 0xE0) ? 1 : 99;
        bool ok = extra != 99 && i + extra < text.size() + 0;
        for (size_t k = 1; ok && k <= extra; ++k)
          ok = i + k < text.size() && (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
        if (!ok)
          return error(file + ":" + std::to_string(line) + ":" + std::to_string(column), "",
                       "this is not UTF-8 text (invalid byte 0x" + hex(c) + "); expected a YAML case file");
        i += extra;
      }
      if (c == '\t' && at_indent)
        return error(file + ":" + std::to_string(line) + ":" + std::to_string(column), "",
                     "a tab in the indentation; YAML indents with spaces only");
      if (c == '\n')
      {
        ++line;
        column = 1;
        at_indent = true;
        continue;
      }
      if (c != ' ' && c != '\t')
        at_indent = false;
      ++column;
    }
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
      error(file, "", "the file is empty; expected a YAML case file (see `magbrush check --explain`)");
  }

  static std::string hex(unsigned char c)
  {
    const char *digits = "0123456789ABCDEF";
    return std::string{digits[c >> 4], digits[c & 15]};
  }

  YAML::Node parse_yaml(const std::string &text)
  {
    try
    {
      YAML::Node root = YAML::Load(text);
      // A quote left open at the end of a value is legal YAML when what follows still parses
      // (the text then runs on over the next lines): refused, as a case file never means it.
      if (const size_t quote = unclosed_quote(text, text.size()); quote != std::string::npos)
        syntax_error(text, mark_at(text, quote), "a quoted value runs on to the next line");
      if (!root.IsMap())
        error(location(root.Mark()), "", "expected the case file to be a YAML section of keys "
                                         "(e.g. 'sleeve:'), found " + node_kind(root));
      return root;
    }
    catch (const YAML::DeepRecursion &e)
    {
      error(location(e.mark), "", "the YAML is nested " + std::to_string(e.depth()) +
                                      " levels deep here; case files are a few levels deep");
    }
    catch (const YAML::Exception &e)
    {
      syntax_error(text, e.mark, e.msg);
    }
    return YAML::Node();
  }

  // A YAML syntax error, quoted: the line with a caret under the column, and a hint. yaml-cpp
  // notices an unclosed '{' or '[' only at the next key, a line or more after it, so for those
  // the error points at the bracket that is never closed; otherwise at yaml-cpp's position,
  // with the line before it for context.
  void syntax_error(const std::string &text, const YAML::Mark &mark, const std::string &message)
  {
    if (mark.line < 0)
      return error(file, "", "YAML syntax error: " + message);
    std::vector<size_t> starts{0}; // byte offset of each line
    for (size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n')
        starts.push_back(i + 1);
    const size_t line = std::min(static_cast<size_t>(mark.line), starts.size() - 1);
    size_t at = std::min(starts[line] + static_cast<size_t>(std::max(mark.column, 0)), text.size());
    std::string hint;
    const bool unclosed_map = message.find("end of map flow") != std::string::npos;
    const bool unclosed_list = message.find("end of sequence flow") != std::string::npos;
    bool moved = false;
    // A quoted value whose quote is not closed on its line: YAML reads on across the lines
    // below as one text and fails wherever that text stops making sense, often far below.
    if (const size_t quote = unclosed_quote(text, at); quote != std::string::npos)
    {
      at = quote;
      moved = true;
      hint = "this quote is not closed on its line: YAML reads the lines below as part of the same text; close "
             "it, or drop the quotes";
    }
    else if (unclosed_map || unclosed_list)
    {
      const size_t opener = unclosed_bracket(text, at, unclosed_map ? '{' : '[');
      if (opener != std::string::npos)
      {
        at = opener;
        moved = true;
      }
      hint = unclosed_map ? "this '{' is never closed: end the section with '}' on the same line, or write it as "
                            "indented 'key: value' lines"
                          : "this '[' is never closed: end the list with ']' on the same line";
    }
    else if (message.find("illegal map value") != std::string::npos)
      hint = "a ':' where YAML expected none: a line indented deeper than the key above it, or a second "
             "'key: value' on one line (keys of one section line up under each other; quote a value that "
             "contains ': ')";
    else if (message.find("end of map not found") != std::string::npos ||
             message.find("end of sequence not found") != std::string::npos)
      hint = "this line's indentation does not match the lines around it: the keys of one section line up "
             "under each other, and '- ' list items sit under their key";
    else
      hint = "YAML may notice a mistake a line or two after it: check the lines above too";
    const size_t l = static_cast<size_t>(std::upper_bound(starts.begin(), starts.end(), at) - starts.begin()) - 1;
    const size_t column = at - starts[l];
    const std::string where = file + ":" + std::to_string(l + 1) + ":" + std::to_string(display_width(text.substr(starts[l], column)) + 1);
    std::string excerpt;
    const auto quote = [&](size_t k) {
      const size_t end = k + 1 < starts.size() ? starts[k + 1] - 1 : text.size();
      std::string content = text.substr(starts[k], end - starts[k]);
      if (!content.empty() && content.back() == '\r')
        content.pop_back();
      if (content.size() > 120)
        content = content.substr(0, 117) + "...";
      const std::string number = std::to_string(k + 1);
      excerpt += "\n    " + std::string(6 - std::min<size_t>(number.size(), 5), ' ') + number + " | " + content;
    };
    // The line before, for context, unless it is blank or the error was moved onto its bracket.
    if (!moved && l > 0 && text.find_first_not_of(" \t\r", starts[l - 1]) < starts[l] - 1)
      quote(l - 1);
    quote(l);
    excerpt += "\n    " + std::string(6, ' ') + " | " + std::string(display_width(text.substr(starts[l], column)), ' ') + "^";
    error(where, "", "YAML syntax error: " + message + excerpt + "\n    hint: " + hint);
  }

  // The YAML mark (line and column, from 0) of byte offset `at` of `text`.
  static YAML::Mark mark_at(const std::string &text, size_t at)
  {
    YAML::Mark m;
    m.pos = static_cast<int>(at);
    m.line = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
    const size_t line_start = text.rfind('\n', at == 0 ? 0 : at - 1);
    m.column = static_cast<int>(at - (line_start == std::string::npos || at == 0 ? 0 : line_start + 1));
    return m;
  }

  // The opening quote (" or ') of the first line before `end` whose quoted text does not close
  // on that line, outside comments; npos if every line closes its quotes.
  static size_t unclosed_quote(const std::string &text, size_t end)
  {
    size_t line_start = 0;
    while (line_start < end && line_start < text.size())
    {
      const size_t line_end = std::min(text.find('\n', line_start), text.size());
      char open = 0;
      size_t opened_at = std::string::npos;
      for (size_t i = line_start; i < line_end; ++i)
      {
        const char c = text[i];
        if (open == 0 && c == '#' && (i == line_start || text[i - 1] == ' ' || text[i - 1] == '\t'))
          break; // a comment
        if (open == 0 && (c == '"' || c == '\'') &&
            (i == line_start || std::string(" \t:[{,-").find(text[i - 1]) != std::string::npos))
        {
          open = c;
          opened_at = i;
        }
        else if (open == '"' && c == '\\')
          ++i; // an escaped character inside "..."
        else if (open != 0 && c == open)
          open = 0;
      }
      if (open != 0)
        return opened_at;
      line_start = line_end + 1;
    }
    return std::string::npos;
  }

  // The last '{' (or '[') before `end` that no '}' (']') closes, outside quotes and comments;
  // npos if there is none.
  static size_t unclosed_bracket(const std::string &text, size_t end, char open)
  {
    std::vector<size_t> stack;
    char quote = 0;
    bool comment = false;
    char previous = '\n'; // the last character before this one that is not a space
    for (size_t i = 0; i < end && i < text.size(); ++i)
    {
      const char c = text[i];
      if (comment)
      {
        comment = c != '\n';
        previous = '\n';
        continue;
      }
      if (quote)
      {
        if (c == '\\' && quote == '"')
          ++i;
        else if (c == quote)
          quote = 0;
        continue;
      }
      const bool starts_scalar = std::string("\n:,[{-?").find(previous) != std::string::npos;
      if (c != ' ' && c != '\t')
        previous = c;
      if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\n'))
        comment = true;
      else if ((c == '"' || c == '\'') && starts_scalar) // a quote inside a plain scalar is text
        quote = c;
      else if (c == '{' || c == '[')
        stack.push_back(i);
      else if ((c == '}' || c == ']') && !stack.empty())
        stack.pop_back();
    }
    for (auto it = stack.rbegin(); it != stack.rend(); ++it)
      if (text[*it] == open)
        return *it;
    return std::string::npos;
  }

  // Characters (not bytes) of UTF-8 text, for the caret's column.
  static size_t display_width(const std::string &s)
  {
    size_t n = 0;
    for (const unsigned char c : s)
      n += (c & 0xC0) != 0x80;
    return n;
  }

  // ---- overrides ----------------------------------------------------------------------
  // "roller.poles.N1.angle=95deg": walks the tree (list elements by name or [index]),
  // creating sections that are absent, and sets the leaf to the YAML value after '='.
  void apply_overrides(YAML::Node &root)
  {
    for (const auto &o : overrides)
    {
      const std::string where = "--set '" + o + "'";
      const auto eq = o.find('=');
      if (eq == std::string::npos || eq == 0)
      {
        error(where, "", "expected key.path=value (e.g. drum.gap=0.3mm)");
        continue;
      }
      const std::string key_path = o.substr(0, eq);
      YAML::Node value;
      try
      {
        value = YAML::Load(o.substr(eq + 1));
      }
      catch (const YAML::Exception &e)
      {
        // The value quoted with a caret (at the unclosed bracket, if that is the error).
        const std::string text = o.substr(eq + 1);
        size_t at = e.mark.line == 0 && e.mark.column >= 0 ? static_cast<size_t>(e.mark.column) : text.size();
        for (const char open : {'{', '['})
          if (e.msg.find(open == '{' ? "end of map flow" : "end of sequence flow") != std::string::npos &&
              unclosed_bracket(text, text.size(), open) != std::string::npos)
            at = unclosed_bracket(text, text.size(), open);
        const bool one_line = text.find('\n') == std::string::npos && text.size() <= 120;
        error(where, key_path,
              "the value is not valid YAML: " + e.msg +
                  (one_line ? "\n      " + text + "\n      " +
                                  std::string(display_width(text.substr(0, std::min(at, text.size()))), ' ') + "^"
                            : std::string()));
        continue;
      }
      // "planes.plate.path[1].time" -> planes, plate, path, [1], time
      std::vector<std::string> parts;
      std::stringstream ss(key_path);
      for (std::string part; std::getline(ss, part, '.');)
      {
        const auto bracket = part.find('[');
        if (bracket != std::string::npos && bracket > 0 && part.back() == ']')
        {
          parts.push_back(part.substr(0, bracket));
          parts.push_back(part.substr(bracket));
        }
        else
          parts.push_back(part);
      }
      std::string display;
      YAML::Node current;
      current.reset(root);
      bool ok = true;
      for (size_t i = 0; ok && i < parts.size(); ++i)
      {
        const std::string &part = parts[i];
        const bool last = (i + 1 == parts.size());
        if (part.empty())
        {
          error(where, key_path, "empty component in the key path");
          ok = false;
          break;
        }
        if (current.IsSequence())
        {
          YAML::Node element;
          if (!find_element(current, part, element))
          {
            error(where, display, "no element '" + part + "' in this list (elements: " +
                                      join(element_names(current), ", ") + ")");
            ok = false;
            break;
          }
          // The same naming as the schema walk: named elements by name, others by [index].
          if (element.IsMap() && element["name"] && element["name"].IsScalar())
            display += "." + element["name"].Scalar();
          else
            display += part;
          if (last)
          {
            error(where, display, "an override replaces a value, not a whole list element");
            ok = false;
            break;
          }
          current.reset(element);
          continue;
        }
        if (!current.IsMap() && !current.IsNull())
        {
          error(where, display, "cannot set a key inside " + node_kind(current));
          ok = false;
          break;
        }
        display += (display.empty() ? "" : ".") + part;
        if (last)
        {
          // Setting one of a pair of alternatives replaces the other one given in the file
          // (--set sleeve.radius=... on a file that gives the diameter).
          for (const auto &[a, b] : alternatives)
            for (const auto &[key, other] : {std::pair{a, b}, std::pair{b, a}})
              if (part == key && current.IsMap() && current[other])
                current.remove(other);
          current[part] = value;
          override_origin[display] = where;
          override_path[o] = display;
        }
        else
        {
          if (!current[part] || current[part].IsNull())
            current[part] = YAML::Node(YAML::NodeType::Map);
          YAML::Node next = current[part];
          current.reset(next);
        }
      }
    }
  }

  // Keys that stand for each other: an override of one replaces the other.
  static constexpr std::pair<const char *, const char *> alternatives[] = {{"radius", "diameter"}};

  static bool is_index(const std::string &part)
  {
    return part.size() >= 3 && part.front() == '[' && part.back() == ']' &&
           part.find_first_not_of("0123456789", 1) == part.size() - 1;
  }

  // The list element addressed by `part` (its name, or [index]); false if there is none.
  static bool find_element(const YAML::Node &list, const std::string &part, YAML::Node &found)
  {
    if (is_index(part))
    {
      const size_t index = part.size() > 12 ? list.size() : std::stoul(part.substr(1, part.size() - 2));
      if (index >= list.size())
        return false;
      found.reset(list[index]);
      return true;
    }
    for (const auto &element : list)
      if (element.IsMap() && element["name"] && element["name"].IsScalar() &&
          element["name"].Scalar() == part)
      {
        found.reset(element);
        return true;
      }
    return false;
  }

  static std::vector<std::string> element_names(const YAML::Node &list)
  {
    std::vector<std::string> names;
    for (size_t i = 0; i < list.size(); ++i)
    {
      const YAML::Node element = list[i];
      if (element.IsMap() && element["name"] && element["name"].IsScalar())
        names.push_back(element["name"].Scalar());
      else
        names.push_back("[" + std::to_string(i) + "]");
    }
    return names;
  }

  // ---- pass 2: the schema walk ---------------------------------------------------------
  void walk_section(const YAML::Node &node, const std::string &pattern, const std::string &display,
                    const YAML::Node &mark_node)
  {
    if (!node.IsMap() && !node.IsNull())
      return error_at(mark_node, display, "expected a section of keys, found " + node_kind(node));
    present.insert(display);
    if (!display.empty() && !locations.count(display))
      locations[display] = location(mark_node.Mark());

    const auto children = child_key_specs(pattern);
    std::set<std::string> seen;
    if (node.IsMap())
      for (auto it = node.begin(); it != node.end(); ++it)
      {
        const YAML::Node key = it->first;
        const YAML::Node child = it->second;
        if (!key.IsScalar())
        {
          error_at(key, display, "expected a key name, found " + node_kind(key));
          continue;
        }
        const std::string name = key.Scalar();
        const std::string child_display = display.empty() ? name : display + "." + name;
        if (!seen.insert(name).second)
        {
          error_at(key, child_display, "duplicate key (given twice in the same section)");
          continue;
        }
        const KeySpec *spec = find_key_spec(pattern.empty() ? name : pattern + "." + name);
        if (!spec)
        {
          std::vector<std::string> valid;
          for (const auto *c : children)
            valid.push_back(last_component(c->path));
          const std::string suggestion = did_you_mean(name, valid);
          error_at(key, child_display,
                   "unknown key '" + name + "'" +
                       (suggestion.empty() ? " (valid keys here: " + join(valid, ", ") + ")"
                                           : " (did you mean '" + suggestion + "'?)"));
          continue;
        }
        locations[child_display] = location(key.Mark());
        walk_node(child, *spec, child_display, key);
      }
    for (const auto *c : children)
      if (c->required && !seen.count(last_component(c->path)))
        error_at(mark_node, display,
                 "missing required key '" + last_component(c->path) + "' (" + c->type_description() +
                     ": " + c->doc + ")");
  }

  void walk_node(const YAML::Node &node, const KeySpec &spec, const std::string &display,
                 const YAML::Node &key)
  {
    switch (spec.type)
    {
    case KeyType::section: return walk_section(node, spec.path, display, key);
    case KeyType::list: return walk_list(node, spec, display, key);
    case KeyType::map: return walk_map(node, spec, display, key);
    default: return walk_leaf(node, spec, display, key);
    }
  }

  void walk_list(const YAML::Node &node, const KeySpec &spec, const std::string &display,
                 const YAML::Node &key)
  {
    present.insert(display);
    items[display];
    if (node.IsNull())
      return;
    if (!node.IsSequence())
      return error_at(node.IsScalar() ? node : key, display,
                      "expected a list ('- name: ...' items), found " + node_kind(node));
    std::set<std::string> names;
    for (size_t i = 0; i < node.size(); ++i)
    {
      const YAML::Node element = node[i];
      std::string item = display + "[" + std::to_string(i) + "]";
      if (element.IsMap() && element["name"] && element["name"].IsScalar())
      {
        const std::string name = element["name"].Scalar();
        if (!names.insert(name).second)
          error_at(element["name"], item, "duplicate name '" + name + "' in " + display);
        else if (!name.empty() && name.find_first_of(".[]= ") == std::string::npos)
          item = display + "." + name;
        item_names[item] = name;
      }
      items[display].push_back(item);
      walk_section(element, spec.path + "[]", item, element);
    }
  }

  void walk_map(const YAML::Node &node, const KeySpec &spec, const std::string &display,
                const YAML::Node &key)
  {
    present.insert(display);
    items[display];
    if (node.IsNull())
      return;
    if (!node.IsMap())
      return error_at(node.IsScalar() ? node : key, display,
                      "expected a section of 'name: {properties}' entries, found " + node_kind(node));
    std::set<std::string> seen;
    for (auto it = node.begin(); it != node.end(); ++it)
    {
      const YAML::Node name_node = it->first;
      if (!name_node.IsScalar())
      {
        error_at(name_node, display, "expected a name, found " + node_kind(name_node));
        continue;
      }
      const std::string name = name_node.Scalar();
      const std::string item = display + "." + name;
      if (!seen.insert(name).second)
      {
        error_at(name_node, item, "duplicate name (given twice)");
        continue;
      }
      items[display].push_back(item);
      item_names[item] = name;
      locations[item] = location(name_node.Mark());
      walk_section(it->second, spec.path + ".*", item, name_node);
    }
  }

  // Where to point for a leaf: the value if it has a position, else its key.
  static const YAML::Node &mark_of(const YAML::Node &value, const YAML::Node &key)
  {
    return value.Mark().line >= 0 ? value : key;
  }

  void walk_leaf(const YAML::Node &node, const KeySpec &spec, const std::string &display,
                 const YAML::Node &key)
  {
    const YAML::Node &at = mark_of(node, key);
    try
    {
      values[display] = leaf_value(node, spec);
      locations[display] = location(at.Mark()); // later (geometric) errors point at the value
    }
    catch (const UnitError &e)
    {
      error_at(at, display, e.what());
    }
  }

  // Converts one leaf; throws UnitError with an expected/found message.
  static Value leaf_value(const YAML::Node &node, const KeySpec &spec)
  {
    Value v;
    v.spec = &spec;
    const auto expected = [&](const std::string &what) {
      throw UnitError("expected " + what + ", found " + node_kind(node));
    };
    const bool scalar_type = spec.type == KeyType::quantity || spec.type == KeyType::integer ||
                             spec.type == KeyType::boolean || spec.type == KeyType::string ||
                             spec.type == KeyType::choice;
    if (scalar_type && !node.IsScalar())
      expected(spec.type_description());
    switch (spec.type)
    {
    case KeyType::quantity:
      v.written = node.Scalar();
      v.number = parse_quantity(v.written, spec.dimension, BareNumber::refused, typical_value(spec));
      check_range(spec, v.number, v.written);
      break;
    case KeyType::integer:
    {
      v.written = node.Scalar();
      const std::string &s = v.written;
      const size_t start = (!s.empty() && (s[0] == '-' || s[0] == '+')) ? 1 : 0;
      if (s.size() == start || s.size() > start + 15 ||
          s.find_first_not_of("0123456789", start) != std::string::npos)
        expected("an integer (e.g. 12300)");
      v.integer = std::stoll(s);
      check_range(spec, static_cast<double>(v.integer), s);
      break;
    }
    case KeyType::boolean:
    {
      v.written = node.Scalar();
      static const std::set<std::string> yes{"true", "True", "TRUE", "yes", "on"},
          no{"false", "False", "FALSE", "no", "off"};
      if (yes.count(v.written))
        v.flag = true;
      else if (no.count(v.written))
        v.flag = false;
      else
        expected("true or false");
      break;
    }
    case KeyType::string:
      v.written = v.text = node.Scalar();
      break;
    case KeyType::choice:
    {
      v.written = v.text = node.Scalar();
      bool ok = false;
      for (const auto &c : spec.choices)
        ok = ok || c == v.text;
      if (!ok)
      {
        const std::string suggestion = did_you_mean(v.text, spec.choices);
        throw UnitError("expected " + spec.type_description() + ", found '" + v.text + "'" +
                        (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)"));
      }
      break;
    }
    case KeyType::vector3:
      v.numbers = point(node, 3, spec.dimension, spec.type_description());
      break;
    case KeyType::polygon:
      if (!node.IsSequence() || node.size() < 3)
        expected("a polygon of at least 3 points [[x, y], ...]");
      if (node.size() > 10000)
        expected("a polygon of at most 10000 points");
      for (const auto &p : node)
        for (double x : point(p, 2, spec.dimension, "a point [x, y] of lengths"))
          v.numbers.push_back(x);
      break;
    case KeyType::box:
      if (!node.IsSequence() || node.size() != 2)
        expected("a box [[xmin, ymin, zmin], [xmax, ymax, zmax]]");
      for (const auto &p : node)
        for (double x : point(p, 3, spec.dimension, "a corner [x, y, z] of lengths"))
          v.numbers.push_back(x);
      break;
    default:
      break;
    }
    return v;
  }

  // The scale a key's values usually have, for the unit suggested for a bare number: its
  // default if non-zero, else the middle of a bounded positive range, else 0 (the dimension's
  // usual scale).
  static double typical_value(const KeySpec &spec)
  {
    if (spec.type == KeyType::quantity && !spec.default_text.empty() && spec.default_text[0] != '<')
    {
      try
      {
        const double d = parse_quantity(spec.default_text, spec.dimension, BareNumber::si);
        if (d != 0.0)
          return d;
      }
      catch (const UnitError &)
      {
      }
    }
    if (spec.min && spec.max && *spec.min > 0.0 && *spec.max > 0.0)
      return std::sqrt(*spec.min * *spec.max);
    return 0.0;
  }

  static std::vector<double> point(const YAML::Node &node, size_t n, Dimension d, const std::string &what)
  {
    if (!node.IsSequence() || node.size() != n)
      throw UnitError("expected " + what + ", found " + node_kind(node));
    std::vector<double> p;
    for (const auto &x : node)
    {
      if (!x.IsScalar())
        throw UnitError("expected " + what + ", found a component that is " + node_kind(x));
      p.push_back(parse_quantity(x.Scalar(), d));
    }
    return p;
  }

  static void check_range(const KeySpec &spec, double v, const std::string &written)
  {
    const bool below = spec.min && (spec.min_inclusive ? v < *spec.min : v <= *spec.min);
    const bool above = spec.max && (spec.max_inclusive ? v > *spec.max : v >= *spec.max);
    if (!below && !above)
      return;
    std::string message = "expected " +
                          (spec.type == KeyType::integer ? std::string("an integer")
                                                         : dimension_description(spec.dimension)) +
                          " " + spec.range_description() + ", found '" + written + "'";
    const std::string pretty = format_quantity(v, spec.dimension);
    if (spec.dimension != Dimension::dimensionless && spec.type == KeyType::quantity && pretty != written)
      message += " (= " + pretty + ")";
    throw UnitError(message);
  }

  // ---- pass 3: assembling the Case -----------------------------------------------------
  // A scope is a section instance: its display path and its schema pattern.
  struct Scope
  {
    std::string display;
    std::string pattern;
    Scope child(const std::string &key) const
    {
      return {display.empty() ? key : display + "." + key, pattern.empty() ? key : pattern + "." + key};
    }
  };

  bool has(const Scope &s, const std::string &key) const { return values.count(s.child(key).display) > 0; }

  const Value &leaf(const Scope &s, const std::string &key)
  {
    const Scope c = s.child(key);
    const auto it = values.find(c.display);
    if (it != values.end())
      return it->second;
    // Schema default, parsed like user input.
    auto d = defaults.find(c.pattern);
    if (d == defaults.end())
    {
      const KeySpec *spec = find_key_spec(c.pattern);
      if (!spec)
        throw std::logic_error("case parser: no schema key " + c.pattern);
      Value v;
      v.spec = spec;
      if (!spec->default_text.empty() && spec->default_text[0] != '<')
        v = leaf_value(YAML::Load(spec->default_text), *spec);
      d = defaults.emplace(c.pattern, v).first;
    }
    return d->second;
  }

  double q(const Scope &s, const std::string &key) { return leaf(s, key).number; }
  long long integer(const Scope &s, const std::string &key) { return leaf(s, key).integer; }
  bool flag(const Scope &s, const std::string &key) { return leaf(s, key).flag; }
  std::string str(const Scope &s, const std::string &key) { return leaf(s, key).text; }
  Vec3 vec3(const Scope &s, const std::string &key)
  {
    const auto &n = leaf(s, key).numbers;
    return n.size() == 3 ? Vec3{n[0], n[1], n[2]} : Vec3{0, 0, 0};
  }

  std::vector<Scope> elements(const Scope &list_scope, const std::string &suffix)
  {
    std::vector<Scope> out;
    for (const auto &item : items[list_scope.display])
      out.push_back({item, list_scope.pattern + suffix});
    return out;
  }

  // radius or diameter, exactly one
  double radius_of(const Scope &s)
  {
    const bool r = has(s, "radius"), d = has(s, "diameter");
    if (r && d)
      error_at_path(s.display + ".diameter", "give either radius or diameter, not both");
    if (!r && !d)
      error_at_path(s.display, "missing required key 'radius' (or 'diameter')");
    return r ? q(s, "radius") : 0.5 * q(s, "diameter");
  }

  // The overrides that change a stored field or mesh: those whose key (or a key under it) the
  // schema marks as a field input (case/case_schema.h, the `affects` mark).
  std::vector<std::string> field_overrides(const Case &c) const
  {
    const std::vector<ResolvedEntry> entries = resolved_entries(c);
    std::vector<std::string> out;
    for (const auto &o : overrides)
    {
      const auto at = override_path.find(o);
      if (at == override_path.end())
        continue;
      const std::string &p = at->second;
      for (const auto &e : entries)
      {
        const KeySpec *spec = find_key_spec(e.pattern);
        const bool under = e.path == p || e.path.rfind(p + ".", 0) == 0 || e.path.rfind(p + "[", 0) == 0;
        if (under && spec && spec->affects != Affects::none)
        {
          out.push_back(o);
          break;
        }
      }
    }
    return normalised_overrides(out);
  }

  Case build()
  {
    Case c;
    const Scope top{"", ""};
    c.source_file = file;
    c.name = has(top, "name") ? str(top, "name") : std::filesystem::path(file).stem().string();
    c.scene = str(top, "scene");
    c.measured_flux_file = str(top, "measured_flux_file");
    if (!c.measured_flux_file.empty() && std::filesystem::path(c.measured_flux_file).is_relative())
      c.measured_flux_file = (std::filesystem::path(file).parent_path() / c.measured_flux_file).lexically_normal().string();
    c.measured_flux_angle_origin = q(top, "measured_flux_angle_origin");

    if (present.count("roller"))
      c.roller = build_roller(top.child("roller"));
    if (present.count("sleeve"))
    {
      const Scope s = top.child("sleeve");
      Sleeve sleeve;
      sleeve.radius = radius_of(s);
      sleeve.thickness = q(s, "thickness");
      sleeve.rpm = q(s, "rpm") * 60.0 / (2.0 * pi);
      sleeve.spin_up_time = q(s, "spin_up_time");
      c.sleeve = sleeve;
    }
    if (present.count("drum"))
    {
      const Scope s = top.child("drum");
      c.drum.present = true;
      c.drum.radius = radius_of(s);
      c.drum.rpm = q(s, "rpm") * 60.0 / (2.0 * pi);
      c.drum.spin_up_time = q(s, "spin_up_time");
      c.drum.gap = q(s, "gap");
      c.drum.angle = q(s, "angle");
      c.drum.pc_thickness = q(s, "pc_thickness");
      c.drum.pc_eps_r = q(s, "pc_eps_r");
    }
    for (const auto &s : elements(top.child("blades"), "[]"))
      c.blades.push_back(build_blade(s, c.sleeve ? c.sleeve->radius : 0.0));
    for (const auto &s : elements(top.child("planes"), "[]"))
      c.planes.push_back(build_plane(s));
    for (const auto &s : elements(top.child("materials"), ".*"))
      c.materials.push_back(build_material(s));
    for (const auto &s : elements(top.child("populations"), "[]"))
      c.populations.push_back(build_population(s));
    for (const auto &s : elements(top.child("adhesion_pairs"), "[]"))
      c.adhesion_pairs.push_back({str(s, "material_a"), str(s, "material_b"), q(s, "hamaker")});
    build_electric(c, top.child("electric"));
    build_applied_field(c, top.child("applied_field"));
    build_field(c.field, top.child("field"));
    build_dem(c.dem, top.child("dem"));
    build_nip(c.nip, top.child("nip"));
    build_compression(c.compression, top.child("compression"));
    const Scope dv = top.child("development");
    c.development.measure_from = q(dv, "measure_from");
    c.development.measure_to = q(dv, "measure_to");
    c.development.sample_interval = q(dv, "sample_interval");
    c.development.average_from = q(dv, "average_from");
    c.development.average_over = str(dv, "average_over");
    c.development.phase_bins = static_cast<int>(integer(dv, "phase_bins"));
    c.development.block_length = q(dv, "block_length");
    const Scope dm = top.child("dma");
    c.dma.after_blade = q(dm, "after_blade");
    c.dma.window = q(dm, "window");
    c.dma.height = q(dm, "height");
    c.dma.front_window = q(dm, "front_window");
    c.dma.release_from = q(dm, "release_from");
    c.dma.release_to = q(dm, "release_to");
    c.dma.sample_interval = q(dm, "sample_interval");
    c.dma.average_from = q(dm, "average_from");
    const Scope st = top.child("statistics");
    c.statistics.steady_drift = q(st, "steady_drift");
    c.statistics.blocks = static_cast<int>(integer(st, "blocks"));
    build_flow(c.flow, top);
    const Scope o = top.child("output");
    c.output.directory = str(o, "directory");
    c.output.vtu = flag(o, "vtu");
    c.output.xdmf = flag(o, "xdmf");
    c.output.overrides = normalised_overrides(overrides);
    // The stored fields belong to the run's results unless the case puts them elsewhere: two
    // runs of one case into two folders (two biases, two tests side by side) then never
    // replace each other's field while the other reads it.
    if (c.output.directory.empty())
    {
      // Named after the case and its overrides (case/run_folder.h); the fields after the
      // overrides that change a field only, so that a DEM-only variant finds its baseline's.
      c.output.automatic = true;
      c.output.directory = automatic_run_folder(c.name, c.output.overrides);
      if (c.field.output_dir.empty())
        c.field.output_dir =
            (std::filesystem::path(automatic_run_folder(c.name, field_overrides(c))) / "fields").string();
    }
    if (c.field.output_dir.empty())
      c.field.output_dir = (std::filesystem::path(c.output.directory) / "fields").string();
    return c;
  }

  Roller build_roller(const Scope &s)
  {
    Roller r;
    r.shaft_radius = q(s, "shaft_radius");
    r.shaft_mu_r = q(s, "shaft_mu_r");
    r.magnet_radius = q(s, "magnet_radius");
    r.magnet_mu_r = q(s, "magnet_mu_r");
    const double default_alpha = q(s, "shape_factor");
    for (const auto &p : elements(s.child("poles"), "[]"))
    {
      Pole pole;
      pole.name = str(p, "name");
      pole.angle = q(p, "angle");
      pole.strength = q(p, "strength");
      pole.shape_factor = has(p, "shape_factor") ? q(p, "shape_factor") : default_alpha;
      if (has(p, "polarity"))
      {
        // An unsigned strength takes the polarity's sign; an explicit sign must agree.
        const double sign = str(p, "polarity") == "N" ? 1.0 : -1.0;
        const std::string &written = leaf(p, "strength").written;
        const bool explicit_sign = written.find_first_of("+-") == written.find_first_not_of(" ");
        if (explicit_sign && pole.strength * sign < 0.0)
          error_at_path(p.display + ".strength",
                        "the strength's sign contradicts 'polarity: " + str(p, "polarity") +
                            "'; give an unsigned strength or drop the polarity");
        pole.strength = sign * std::abs(pole.strength);
      }
      r.poles.push_back(pole);
    }
    return r;
  }

  BladeOrGuide build_blade(const Scope &s, double sleeve_radius)
  {
    BladeOrGuide b;
    b.name = str(s, "name");
    b.is_doctor_blade = str(s, "kind") == "doctor_blade";
    b.mu_r = q(s, "mu_r");
    b.material = str(s, "material");
    const bool profile = has(s, "profile");
    const std::vector<std::string> generated_keys{"angle", "thickness", "length"};
    std::vector<std::string> given, missing;
    for (const auto &k : generated_keys)
      (has(s, k) ? given : missing).push_back(k);
    if (profile)
    {
      if (!given.empty())
        error_at_path(s.child(given.front()).display,
                      "give either 'profile' or angle + gap + thickness + length, not both");
      const auto &n = leaf(s, "profile").numbers;
      for (size_t i = 0; i + 1 < n.size(); i += 2)
        b.polygon.push_back({n[i], n[i + 1]});
      if (has(s, "gap"))
        b.gap = q(s, "gap"); // checked against the polygon in validate_case
      else
        b.gap = -1.0;        // derived below by validate_case's helper
    }
    else
    {
      if (!has(s, "gap"))
        missing.push_back("gap");
      if (!missing.empty())
      {
        error_at_path(s.display, "a blade needs either 'profile' or angle + gap + thickness + length; missing: " +
                                     join(missing, ", "));
        return b;
      }
      b.gap = q(s, "gap");
      b.polygon = generated_blade_polygon(sleeve_radius, q(s, "angle"), b.gap, q(s, "thickness"), q(s, "length"));
    }
    if (b.polygon.size() >= 3 && polygon_signed_area(b.polygon) < 0.0)
      std::reverse(b.polygon.begin(), b.polygon.end()); // the contract is counter-clockwise
    if (b.gap < 0.0 && sleeve_radius > 0.0 && b.polygon.size() >= 3)
      b.gap = polygon_distance_to_point(b.polygon, {0.0, 0.0}) - sleeve_radius;
    return b;
  }

  PlaneWall build_plane(const Scope &s)
  {
    PlaneWall p;
    p.name = str(s, "name");
    p.point = vec3(s, "point");
    p.normal = vec3(s, "normal");
    const double n = std::sqrt(p.normal[0] * p.normal[0] + p.normal[1] * p.normal[1] + p.normal[2] * p.normal[2]);
    if (n > 0.0)
      for (auto &x : p.normal)
        x /= n;
    p.material = str(s, "material");
    for (const auto &e : elements(s.child("path"), "[]"))
      p.path.emplace_back(q(e, "time"), vec3(e, "displacement"));
    return p;
  }

  Material build_material(const Scope &s)
  {
    Material m;
    m.name = item_names[s.display];
    m.youngs_modulus = q(s, "youngs_modulus");
    m.poisson_ratio = q(s, "poisson_ratio");
    m.density = q(s, "density");
    m.mu_r = q(s, "mu_r");
    m.saturation_magnetisation = q(s, "saturation_magnetisation");
    m.friction = q(s, "friction");
    m.rolling_friction = q(s, "rolling_friction");
    m.polygon_angles = static_cast<int>(integer(s, "polygon_angles"));
    m.damping = q(s, "damping");
    m.restitution = q(s, "restitution");
    m.hamaker = q(s, "hamaker");
    m.hamaker_given = has(s, "hamaker");
    m.adhesion_radius = q(s, "adhesion_radius");
    return m;
  }

  Population build_population(const Scope &s)
  {
    Population p;
    p.name = str(s, "name");
    p.kind = str(s, "kind") == "toner" ? ParticleKind::toner : ParticleKind::carrier;
    p.material = has(s, "material") ? str(s, "material") : str(s, "kind");
    p.diameter_mean = q(s, "diameter");
    p.diameter_std = q(s, "diameter_std");
    p.count = static_cast<long>(integer(s, "count"));
    p.mass = q(s, "mass");
    p.concentration = q(s, "concentration");
    p.charge_to_mass = q(s, "charge_to_mass");
    p.charge_to_mass_std = q(s, "charge_to_mass_std");
    p.wrong_sign_fraction = q(s, "wrong_sign_fraction");
    p.counter_charge = flag(s, "counter_charge");
    p.attached = flag(s, "attached");
    p.carried_until_gap = q(s, "carried_until_gap");
    if (has(s, "insert_box"))
    {
      const auto &n = leaf(s, "insert_box").numbers;
      p.insert_box = std::array<Vec3, 2>{Vec3{n[0], n[1], n[2]}, Vec3{n[3], n[4], n[5]}};
    }
    p.layer_thickness = q(s, "layer_thickness");
    return p;
  }

  void build_electric(Case &c, const Scope &s)
  {
    c.electric.enabled = present.count(s.display) && flag(s, "enabled");
    c.electric.bias = q(s, "bias");
    const Scope image = s.child("image");
    const bool potentials = has(image, "dark_potential") || has(image, "light_potential");
    const bool charges = has(image, "dark_charge") || has(image, "light_charge");
    auto &li = c.electric.image;
    if (potentials && charges)
      error_at_path(image.display, "give the latent image as potentials or as charges, not both");
    else if (potentials || charges)
    {
      const std::string dark = potentials ? "dark_potential" : "dark_charge";
      const std::string light = potentials ? "light_potential" : "light_charge";
      for (const auto &k : {dark, light})
        if (!has(image, k))
          error_at_path(image.display, "missing '" + k + "' (the latent image needs both dark and light values)");
      li.kind = potentials ? LatentImage::Kind::surface_potential : LatentImage::Kind::surface_charge;
      li.dark_value = q(image, dark);
      li.light_value = q(image, light);
    }
    li.period = q(image, "period");
    li.duty = q(image, "duty");
    c.electric.coulomb = flag(s, "coulomb");
    c.electric.coulomb_order = static_cast<int>(integer(s, "coulomb_order"));
    c.electric.coulomb_cell = q(s, "coulomb_cell");
    c.electric.coulomb_refresh = q(s, "coulomb_refresh");
    c.electric.conductor_images = flag(s, "conductor_images");
    c.electric.pair_image_terms = static_cast<int>(integer(s, "pair_image_terms"));
    c.electric.hold_distance = q(s, "hold_distance");
    c.electric.coulomb_hold_frame =
      str(s, "coulomb_hold_frame") == "sleeve" ? Electric::HoldFrame::sleeve : Electric::HoldFrame::lab;
    li.edge_width = q(image, "edge_width");
    if (li.period > 0.0 && li.edge_width > std::min(li.duty, 1.0 - li.duty) * li.period)
      error_at_path(image.display, "edge_width " + std::to_string(li.edge_width * 1e6) +
                                     " um is wider than the narrower strip (min(duty, 1 - duty) x period = " +
                                     std::to_string(std::min(li.duty, 1.0 - li.duty) * li.period * 1e6) +
                                     " um): the edges of one strip would overlap");
  }

  void build_applied_field(Case &c, const Scope &s)
  {
    auto &f = c.applied_field;
    const std::string kind = str(s, "kind");
    if (kind == "auto")
      f.kind = c.roller ? AppliedField::Kind::roller : AppliedField::Kind::none;
    else
      f.kind = kind == "roller" ? AppliedField::Kind::roller
               : kind == "uniform" ? AppliedField::Kind::uniform : AppliedField::Kind::none;
    f.uniform_direction = vec3(s, "direction");
    const double n = std::sqrt(f.uniform_direction[0] * f.uniform_direction[0] +
                               f.uniform_direction[1] * f.uniform_direction[1] +
                               f.uniform_direction[2] * f.uniform_direction[2]);
    if (n > 0.0)
      for (auto &x : f.uniform_direction)
        x /= n;
    else
      error_at_path(s.child("direction").display, "expected a non-zero direction, found [0, 0, 0]");
    f.uniform_magnitude = q(s, "magnitude");
    f.ramp_time = q(s, "ramp_time");
    for (const auto &e : elements(s.child("schedule"), "[]"))
      f.schedule.emplace_back(q(e, "time"), q(e, "magnitude"));
    if (!f.schedule.empty())
    {
      for (const char *k : {"magnitude", "ramp_time"})
        if (has(s, k) && q(s, k) != 0.0)
          error_at_path(s.child(k).display, std::string("give either a schedule or ") + k +
                                                " (the schedule sets |B|(t) itself); remove one of them (or set it to 0)");
      f.uniform_magnitude = 0.0;
      for (const auto &[t, b] : f.schedule)
        f.uniform_magnitude = std::max(f.uniform_magnitude, b);
    }
  }

  void build_compression(CompressionSettings &m, const Scope &s)
  {
    m.plate = str(s, "plate");
    m.stage = str(s, "stage");
    m.sample_interval = q(s, "sample_interval");
    m.average_window = q(s, "average_window");
    m.map_interval = q(s, "map_interval");
  }

  void build_flow(FlowSettings &f, const Scope &top)
  {
    const Scope in = top.child("inflow"), out = top.child("outflow"), report = top.child("flow_report");
    f.inflow_population = str(in, "population");
    f.inflow_areal_mass = q(in, "areal_mass");
    f.inflow_angle = q(in, "angle");
    f.inflow_layer_height = q(in, "layer_height");
    f.inflow_supply = str(in, "supply");
    f.inflow_prefill_arc = q(in, "prefill_arc");
    f.inflow_prefill_no_room = str(in, "prefill_where_no_room");
    f.inflow_sump_mass = q(in, "sump_mass");
    f.interval = q(in, "interval");
    f.outflow_angle = q(out, "angle");
    f.outflow_width = q(out, "width");
    f.outflow_radius = q(out, "outer_radius");
    f.sample_interval = q(report, "sample_interval");
    f.flux_angle = q(report, "flux_angle");
    f.density_window = q(report, "density_window");
    f.average_from = q(report, "average_from");
  }

  void build_field(FieldSettings &f, const Scope &s)
  {
    f.mesh_size_far = q(s, "mesh_size_far");
    f.mesh_size_sleeve = q(s, "mesh_size_sleeve");
    f.mesh_size_gap = q(s, "mesh_size_gap");
    f.element_degree = static_cast<int>(integer(s, "element_degree"));
    f.outer_radius_factor = q(s, "outer_radius_factor");
    f.grid_radial_spacing = q(s, "grid_radial_spacing");
    f.grid_angular_spacing = q(s, "grid_angular_spacing");
    f.grid_outer_radius = q(s, "grid_outer_radius");
    f.grid_electric_spacing = q(s, "grid_electric_spacing");
    f.electric_phase_samples = static_cast<int>(integer(s, "electric_phase_samples"));
    f.probe_radius = q(s, "probe_radius");
    f.output_dir = str(s, "output_dir");
  }

  void build_nip(NipSettings &n, const Scope &s)
  {
    n.average_from = q(s, "average_from");
    n.sample_interval = q(s, "sample_interval");
    n.bin_width = q(s, "bin_width");
    n.half_width = q(s, "half_width");
    n.chain_bin_angle = q(s, "chain_bin_angle");
    n.chain_half_angle = q(s, "chain_half_angle");
  }

  void build_dem(DemSettings &d, const Scope &s)
  {
    d.time_step = q(s, "time_step");
    d.time_step_safety = q(s, "time_step_safety");
    d.duration = q(s, "duration");
    d.leg = flag(s, "leg");
    d.output_interval = q(s, "output_interval");
    d.checkpoint_interval = q(s, "checkpoint_interval");
    d.checkpoint_wall_interval = q(s, "checkpoint_wall_interval");
    d.periodic_length = q(s, "periodic_length");
    d.periodic_length_x = q(s, "periodic_length_x");
    d.periodic_length_y = q(s, "periodic_length_y");
    d.magnetic_model = str(s, "magnetic_model");
    d.magnetic_cutoff = q(s, "magnetic_cutoff");
    d.magnetic_refresh = q(s, "magnetic_refresh");
    d.magnetic_tolerance = q(s, "magnetic_tolerance");
    d.verlet_skin = q(s, "verlet_skin");
    d.magnetic_far_field = str(s, "magnetic_far_field");
    d.magnetic_far_order = static_cast<int>(integer(s, "magnetic_far_order"));
    d.magnetic_far_cell = q(s, "magnetic_far_cell");
    d.magnetic_staleness = q(s, "magnetic_staleness");
    d.magnetic_staleness_mode = str(s, "magnetic_staleness_mode");
    d.magnetic_hold = str(s, "magnetic_hold");
    d.magnetic_skin = q(s, "magnetic_skin");
    d.magnetic_live_steps = static_cast<int>(integer(s, "magnetic_live_steps"));
    d.air_viscosity = q(s, "air_viscosity");
    d.gravity = vec3(s, "gravity");
    d.seed = static_cast<unsigned long>(integer(s, "seed"));
    d.threads = static_cast<int>(integer(s, "threads"));
    d.max_overlap_fraction = q(s, "max_overlap_fraction");
    d.restitution_model = str(s, "restitution_model");
    d.settle_time = q(s, "settle_time");
    d.max_kinetic_energy_growth = q(s, "max_kinetic_energy_growth");
    d.adhesion_cutoff = q(s, "adhesion_cutoff");
    d.adhesion_range_fraction = q(s, "adhesion_range_fraction");
    d.toner_stiffness_factor = q(s, "toner_stiffness_factor");
    d.toner_substeps = static_cast<int>(integer(s, "toner_substeps"));
  }
};

} // namespace

Case parse_case_text(const std::string &yaml_text, const std::string &file_name_for_errors,
                     const std::vector<std::string> &overrides)
{
  CaseReader reader(file_name_for_errors, overrides);
  try
  {
    return reader.read(yaml_text);
  }
  catch (const CaseError &)
  {
    throw;
  }
  catch (const YAML::Exception &e)
  {
    // Anything yaml-cpp throws outside parsing (e.g. an unexpected node shape).
    throw CaseError("invalid case '" + file_name_for_errors + "':\n  " + file_name_for_errors + ": " + e.what());
  }
}

Case load_case(const std::string &path, const std::vector<std::string> &overrides)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status))
    throw CaseError("cannot read case '" + path + "': no such file (expected a YAML case file, e.g. cases/kawamoto_nip.yaml)");
  if (fs::is_directory(status))
    throw CaseError("cannot read case '" + path + "': it is a directory, expected a YAML case file");
  if (!fs::is_regular_file(status))
    throw CaseError("cannot read case '" + path + "': not a regular file, expected a YAML case file");
  const auto size = fs::file_size(path, ec);
  if (!ec && size > max_case_file_bytes)
    throw CaseError("cannot read case '" + path + "': the file has " + std::to_string(size) +
                    " bytes; case files are small YAML text files (limit " + std::to_string(max_case_file_bytes) + " bytes)");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw CaseError("cannot read case '" + path + "': the file cannot be opened (permissions?)");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_case_text(text.str(), path, overrides);
}

} // namespace magbrush
