// The inverse of a finished study (see study_inverse.h).
#include "design/study_inverse.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace {

// The cells of a CSV line; quotes around a cell are dropped (no commas inside quotes here).
std::vector<std::string> split(const std::string &line)
{
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');)
  {
    while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ' || cell.back() == '"'))
      cell.pop_back();
    while (!cell.empty() && (cell.front() == ' ' || cell.front() == '"'))
      cell.erase(cell.begin());
    out.push_back(cell);
  }
  return out;
}

double number(const std::string &s)
{
  try
  {
    size_t used = 0;
    const double v = std::stod(s, &used);
    return used == s.size() ? v : NAN;
  }
  catch (const std::exception &)
  {
    return NAN;
  }
}

int column(const std::vector<std::string> &header, const std::string &name)
{
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : int(it - header.begin());
}

// The varied column in SI: "<key> [unit]" as the sweep writes it, else "<key>" itself.
int varied_column(const std::vector<std::string> &header, const std::string &key)
{
  for (size_t j = 0; j < header.size(); ++j)
    if (header[j].rfind(key + " [", 0) == 0)
      return int(j);
  return column(header, key);
}

std::string listed(const std::vector<std::string> &header)
{
  std::string s;
  for (const auto &h : header)
    s += (s.empty() ? "" : ", ") + h;
  return s;
}

struct Line
{
  double a = 0, b = 0;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  double chi2_per_dof = 0;
};

// y = a + b x weighted by 1/σ² (equal weights when any point lacks a standard error).
Line weighted_line(const std::vector<StudySample> &p)
{
  const bool weighted = std::all_of(p.begin(), p.end(), [](const StudySample &q) { return q.se > 0; });
  Eigen::MatrixXd X(p.size(), 2);
  Eigen::VectorXd y(p.size()), w(p.size());
  for (size_t k = 0; k < p.size(); ++k)
  {
    X(k, 0) = 1.0;
    X(k, 1) = p[k].x;
    y(k) = p[k].y;
    w(k) = weighted ? 1.0 / (p[k].se * p[k].se) : 1.0;
  }
  const Eigen::MatrixXd XtW = X.transpose() * w.asDiagonal();
  const Eigen::Matrix2d A = XtW * X;
  const Eigen::Vector2d c = A.ldlt().solve(XtW * y);
  Line l;
  l.a = c(0);
  l.b = c(1);
  const Eigen::VectorXd r = y - X * c;
  const double dof = double(p.size()) - 2.0;
  const double chi2 = (r.array().square() * w.array()).sum();
  l.chi2_per_dof = dof > 0 ? chi2 / dof : 0.0;
  // Without standard errors the scatter about the line is the only error estimate.
  const double scale = weighted ? std::max(1.0, l.chi2_per_dof) : (dof > 0 ? l.chi2_per_dof : 0.0);
  l.cov = A.inverse() * scale;
  return l;
}

bool strictly_monotone(const std::vector<StudySample> &p)
{
  bool up = true, down = true;
  for (size_t k = 1; k < p.size(); ++k)
  {
    up &= p[k].y > p[k - 1].y;
    down &= p[k].y < p[k - 1].y;
  }
  return up || down;
}

std::string g(double v)
{
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

} // namespace

StudyTable read_study_table(const std::string &path, const std::string &x_key, const std::string &y_key)
{
  std::ifstream in(path);
  if (!in)
    throw std::invalid_argument("cannot read the study table " + path + " (a finished `magbrush sweep` writes sweep_summary.csv)");
  StudyTable t;
  t.source = path;
  t.x_key = x_key;
  t.y_key = y_key;
  std::string line;
  std::vector<std::string> header;
  while (std::getline(in, line))
  {
    if (line.empty())
      continue;
    if (line[0] == '#')
    {
      const std::string mark = "# magbrush sweep of ";
      if (line.rfind(mark, 0) == 0)
        t.case_path = line.substr(mark.size());
      continue;
    }
    header = split(line);
    break;
  }
  const int xc = varied_column(header, x_key), yc = column(header, y_key), sc = column(header, y_key + "_stderr");
  const int status = column(header, "status"), label = column(header, "point");
  if (xc < 0 || yc < 0)
    throw std::invalid_argument(path + ": no column " + (xc < 0 ? "'" + x_key + " [unit]'" : "'" + y_key + "'") +
                                " (columns: " + listed(header) + "); pick them with --key and --quantity");
  while (std::getline(in, line))
  {
    if (line.empty() || line[0] == '#')
      continue;
    const auto c = split(line);
    StudySample p;
    p.label = label >= 0 && label < int(c.size()) ? c[label] : "row";
    if (status >= 0 && status < int(c.size()) && c[status] != "ok")
    {
      t.notes.push_back(p.label + " skipped: status " + c[status]);
      continue;
    }
    p.x = xc < int(c.size()) ? number(c[xc]) : NAN;
    p.y = yc < int(c.size()) ? number(c[yc]) : NAN;
    p.se = sc >= 0 && sc < int(c.size()) ? number(c[sc]) : 0.0;
    if (!std::isfinite(p.se))
      p.se = 0.0;
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
    {
      t.notes.push_back(p.label + " skipped: no value");
      continue;
    }
    t.points.push_back(p);
  }
  std::sort(t.points.begin(), t.points.end(), [](const StudySample &a, const StudySample &b) { return a.x < b.x; });
  if (t.points.size() < 2)
    throw std::invalid_argument(path + ": " + std::to_string(t.points.size()) +
                                " usable point(s); the inverse needs at least two");
  return t;
}

StudyAnswer invert_study(const StudyTable &table, double target, StudyAnswer::Method method)
{
  const auto &p = table.points;
  StudyAnswer a;
  a.monotone = strictly_monotone(p);
  const Line line = weighted_line(p);
  a.slope = line.b;
  a.slope_se = std::sqrt(line.cov(1, 1));
  a.chi2_per_dof = line.chi2_per_dof;
  const auto [lo, hi] = std::minmax_element(p.begin(), p.end(), [](const StudySample &u, const StudySample &v) { return u.y < v.y; });
  a.inside = target >= lo->y && target <= hi->y;
  const bool piecewise = method == StudyAnswer::Method::piecewise ||
                         (method == StudyAnswer::Method::automatic && a.monotone);
  if (piecewise && a.inside)
    for (size_t i = 0; i + 1 < p.size(); ++i)
    {
      const double y0 = p[i].y, y1 = p[i + 1].y;
      if ((target - y0) * (target - y1) > 0 || y0 == y1)
        continue;
      const double t = (target - y0) / (y1 - y0), dx = p[i + 1].x - p[i].x, dy = y1 - y0;
      a.method = StudyAnswer::Method::piecewise;
      a.x = p[i].x + t * dx;
      a.se = std::abs(dx / dy) * std::hypot((1 - t) * p[i].se, t * p[i + 1].se);
      a.how = "piecewise linear between " + p[i].label + " and " + p[i + 1].label + " (t = " + g(t) + ")";
      return a;
    }
  // The weighted line: x* = (T − a)/b, σ² = gᵀ C g with g = (−1/b, −(T − a)/b²).
  if (line.b == 0.0)
    throw std::invalid_argument("the study's quantity does not change with the varied value: no answer");
  a.method = StudyAnswer::Method::line;
  a.x = (target - line.a) / line.b;
  const Eigen::Vector2d grad(-1.0 / line.b, -(target - line.a) / (line.b * line.b));
  a.se = std::sqrt(grad.dot(line.cov * grad));
  a.how = std::string("weighted straight line through ") + std::to_string(p.size()) + " points (slope " + g(line.b) +
          " ± " + g(a.slope_se) + ", χ²/dof " + g(line.chi2_per_dof) + ")" +
          (a.inside ? (a.monotone || method == StudyAnswer::Method::line ? "" : "; the means are not monotone")
                    : "; EXTRAPOLATED: the target lies outside the study");
  return a;
}

} // namespace magbrush
