// The active study's next point (see study_refinement.h).
#include "design/study_refinement.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace magbrush {

RefinementPlan plan_refinement(const StudyTable &table, double target, StudyAnswer::Method method, int candidates)
{
  const StudyAnswer now = invert_study(table, target, method);
  if (!now.inside)
    throw std::invalid_argument("the target lies outside the study: a point inside it does not narrow an "
                                "extrapolation (extend the study towards the target instead)");
  const auto &p = table.points; // sorted by x
  // Where the candidates go, and what the study predicts of a point at x.
  double from = p.front().x, to = p.back().x, slope = now.slope;
  auto predicted_se = [&](double) {
    return std::accumulate(p.begin(), p.end(), 0.0, [](double s, const StudySample &q) { return s + q.se; }) /
           double(p.size());
  };
  std::function<double(double)> se_at = predicted_se;
  if (now.method == StudyAnswer::Method::piecewise)
  {
    size_t i = 0;
    while (i + 2 < p.size() && !(now.x >= p[i].x && now.x <= p[i + 1].x))
      ++i;
    from = p[i].x;
    to = p[i + 1].x;
    slope = (p[i + 1].y - p[i].y) / (p[i + 1].x - p[i].x);
    const StudySample a = p[i], b = p[i + 1];
    se_at = [a, b](double x) { return a.se + (x - a.x) / (b.x - a.x) * (b.se - a.se); };
  }
  RefinementPlan best;
  best.se_now = now.se;
  best.se_after = INFINITY;
  for (int k = 1; k <= candidates; ++k)
  {
    const double x = from + (to - from) * k / (candidates + 1);
    StudySample c;
    c.label = "candidate";
    c.x = x;
    c.y = target + slope * (x - now.x); // on the study's own curve: the answer stays put
    c.se = se_at(x);
    StudyTable t = table;
    t.points.insert(std::upper_bound(t.points.begin(), t.points.end(), c,
                                     [](const StudySample &u, const StudySample &v) { return u.x < v.x; }),
                    c);
    const StudyAnswer after = invert_study(t, target, method);
    const bool better = after.se < best.se_after * (1 - 1e-12) ||
                        (after.se <= best.se_after * (1 + 1e-12) && std::abs(x - now.x) < std::abs(best.x - now.x));
    if (better)
    {
      best.x = x;
      best.predicted_y = c.y;
      best.predicted_se = c.se;
      best.se_after = after.se;
    }
  }
  return best;
}

} // namespace magbrush
