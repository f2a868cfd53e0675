// The design's page (see design_page.h): one list of sections, written twice, as Markdown and
// as HTML, so that the two never say different things.
#include "app/design_page.h"

#include "common/atomic_file.h"

#include <cstdio>
#include <sstream>

namespace magbrush {

namespace {

struct Table
{
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Section
{
  std::string title;
  std::vector<std::string> paragraphs;
  Table table;
  std::string image;
};

std::string number(double v, const char *format = "%.3f")
{
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string target_text(const RequirementResult &r)
{
  const char *op = r.kind == RequirementResult::Kind::equal ? "=" : r.kind == RequirementResult::Kind::at_most ? "≤" : "≥";
  return std::string(op) + " " + number(r.target, "%.2f") + (r.tolerance > 0 ? " ± " + number(r.tolerance, "%.2f") : "") +
         " " + r.unit;
}

std::string verdict_text(const RequirementResult &r)
{
  return r.met() ? "met (margin " + number(-r.miss, "%.2f") + " " + r.unit + ")"
                 : "MISSED by " + number(r.miss, "%.2f") + " " + r.unit;
}

std::string escaped(const std::string &s)
{
  std::string out;
  for (char c : s)
    out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return out;
}

// A Markdown table cell: its own bars (|Bn|, |M|) would end the cell.
std::string cell(const std::string &s)
{
  std::string out;
  for (char c : s)
    out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::vector<Section> sections_of(const DesignPage &p)
{
  std::vector<Section> s;
  s.push_back({"Verdict", {p.verdict, p.method, p.time}, {}, ""});
  if (!p.image.empty())
    s.push_back({"Profile against the target", {"Bn and Bt of the designed layout (exact ring; the FEM check dashed), "
                                                "the case's layout in grey, the target's band and boxes; below, |B| "
                                                "with the arcs where it must stay low."},
                 {}, p.image});
  Section req{"Requirements", {"Judged on the exact ring of the designed layout" +
                                   std::string(p.fem.empty() ? "." : ", then on the finite-element profile of the "
                                                                     "designed case (the FEM check).")},
              {}, ""};
  req.table.header = {"requirement", "target", "exact ring", "verdict"};
  if (!p.fem.empty())
    req.table.header.insert(req.table.header.end(), {"FEM", "verdict (FEM)"});
  req.table.header.push_back("where");
  for (size_t k = 0; k < p.ring.size(); ++k)
  {
    const auto &r = p.ring[k];
    std::vector<std::string> row = {r.name, target_text(r), number(r.value), verdict_text(r)};
    if (!p.fem.empty())
      row.insert(row.end(), {number(p.fem[k].value), verdict_text(p.fem[k])});
    row.push_back(r.detail);
    req.table.rows.push_back(row);
  }
  if (!p.fem_note.empty())
    req.paragraphs.push_back(p.fem_note);
  s.push_back(req);
  Section layout{"Layout", {"Each pole's angle and |M| (signs and shape factors as the case's), with its box."}, {}, ""};
  layout.table.header = {"pole", "angle, case [deg]", "angle, designed [deg]", "|M|, case [kA/m]",
                         "|M|, designed [kA/m]", "box"};
  layout.table.rows = p.layout;
  s.push_back(layout);
  if (!p.binding.empty())
  {
    Section b{"Constraints at their limit", {}, {}, ""};
    b.table.header = {"constraint"};
    for (const auto &line : p.binding)
      b.table.rows.push_back({line});
    s.push_back(b);
  }
  Section sens{"Sensitivity", {"Change of each requirement's value per +1° of a pole's angle or per +10 kA/m of "
                               "its |M| (central differences on the exact ring at the designed layout): a tolerance "
                               "on a pole's placement or magnetisation times its entry is what it costs the "
                               "requirement."},
               {}, ""};
  sens.table.header = {"requirement"};
  for (size_t j = 0; j < p.sensitivity.parameters.size(); ++j)
    sens.table.header.push_back(p.sensitivity.parameters[j] + (p.sensitivity.per_degree[j] ? " per °" : " per 10 kA/m"));
  for (size_t i = 0; i < p.sensitivity.requirements.size(); ++i)
  {
    std::vector<std::string> row = {p.sensitivity.requirements[i]};
    for (size_t j = 0; j < p.sensitivity.parameters.size(); ++j)
      row.push_back(number(p.sensitivity.d(i, j), "%+.3g"));
    sens.table.rows.push_back(row);
  }
  s.push_back(sens);
  Section files{"Files", {}, {}, ""};
  files.table.header = {"file"};
  for (const auto &f : p.files)
    files.table.rows.push_back({f});
  s.push_back(files);
  return s;
}

std::string markdown(const DesignPage &p, const std::vector<Section> &sections)
{
  std::ostringstream md;
  md << "# magbrush design poles: " << p.case_name << "\n\nTarget: `" << p.target << "`\n\n";
  for (const auto &s : sections)
  {
    md << "## " << s.title << "\n\n";
    for (const auto &para : s.paragraphs)
      if (!para.empty())
        md << para << "\n\n";
    if (!s.image.empty())
      md << "![" << s.image << "](" << s.image << ")\n\n";
    if (s.table.header.empty())
      continue;
    const bool files = s.title == "Files";
    if (files)
    {
      for (const auto &r : s.table.rows)
        md << "* [" << r[0] << "](" << r[0] << ")\n";
      md << "\n";
      continue;
    }
    md << "|";
    for (const auto &h : s.table.header)
      md << " " << cell(h) << " |";
    md << "\n|";
    for (size_t k = 0; k < s.table.header.size(); ++k)
      md << "---|";
    md << "\n";
    for (const auto &r : s.table.rows)
    {
      md << "|";
      for (const auto &c : r)
        md << " " << cell(c) << " |";
      md << "\n";
    }
    md << "\n";
  }
  return md.str();
}

std::string html(const DesignPage &p, const std::vector<Section> &sections)
{
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset='utf-8'><title>magbrush design poles: " << escaped(p.case_name)
    << "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;} table{border-collapse:collapse;}"
       " td,th{border:1px solid #bbb;padding:3px 8px;} img{max-width:100%;margin:6px 0;}</style></head><body>\n"
    << "<h1>magbrush design poles: " << escaped(p.case_name) << "</h1>\n<p>Target: <code>" << escaped(p.target)
    << "</code></p>\n";
  for (const auto &s : sections)
  {
    h << "<h2>" << escaped(s.title) << "</h2>\n";
    for (const auto &para : s.paragraphs)
      if (!para.empty())
        h << "<p>" << escaped(para) << "</p>\n";
    if (!s.image.empty())
      h << "<p><a href='" << s.image << "'><img src='" << s.image << "' alt='" << s.image << "'></a></p>\n";
    if (s.table.header.empty())
      continue;
    if (s.title == "Files")
    {
      h << "<ul>\n";
      for (const auto &r : s.table.rows)
        h << "<li><a href='" << escaped(r[0]) << "'>" << escaped(r[0]) << "</a></li>\n";
      h << "</ul>\n";
      continue;
    }
    h << "<table><tr>";
    for (const auto &c : s.table.header)
      h << "<th>" << escaped(c) << "</th>";
    h << "</tr>\n";
    for (const auto &r : s.table.rows)
    {
      h << "<tr>";
      for (const auto &c : r)
        h << "<td>" << escaped(c) << "</td>";
      h << "</tr>\n";
    }
    h << "</table>\n";
  }
  h << "</body></html>\n";
  return h.str();
}

} // namespace

void write_design_page(const std::string &dir, const DesignPage &page)
{
  const auto sections = sections_of(page);
  write_text_atomically(dir + "/index.md", markdown(page, sections));
  write_text_atomically(dir + "/index.html", html(page, sections));
}

} // namespace magbrush
