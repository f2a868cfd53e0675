// Bounded least squares for the pole layout (see pole_design.h).
#include "design/pole_design.h"

#include <Eigen/Dense>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

namespace magbrush {

namespace {

constexpr double deg = M_PI / 180.0;

std::string f2(double v)
{
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::vector<DesignParameter> free_parameters(const std::vector<Pole> &poles,
                                             const std::vector<PoleLimits> &limits,
                                             double max_strength)
{
  std::vector<DesignParameter> out;
  for (size_t i = 0; i < poles.size(); ++i)
  {
    if (limits[i].fixed)
      continue;
    if (limits[i].angle_high > limits[i].angle_low)
      out.push_back({i, true, limits[i].angle_low, limits[i].angle_high, false});
    if (limits[i].strength_high > limits[i].strength_low)
      out.push_back({i, false, limits[i].strength_low, limits[i].strength_high,
                     limits[i].strength_high == max_strength});
  }
  return out;
}

// The least-squares problem in the unbounded u (Eigen's functor interface for NumericalDiff).
class DesignFunctor
{
public:
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  DesignFunctor(const RingProfile &ring, const RequirementSet &requirements,
                const std::vector<Pole> &base, const std::vector<DesignParameter> &parameters,
                double lambda)
      : ring_(&ring), requirements_(&requirements), base_(base), parameters_(parameters), lambda_(lambda)
  {
    m_requirements_ = requirements_->stacked_residuals(requirements_->evaluate(base_, ring_->of(base_))).size();
  }

  int inputs() const { return int(parameters_.size()); }
  int values() const { return int(m_requirements_ + parameters_.size()); }

  // p = low + (high − low)(1 + sin u)/2, and back (clamped inside, where sin is not flat).
  double physical(size_t j, double u) const
  {
    const auto &q = parameters_[j];
    return q.low + (q.high - q.low) * 0.5 * (1.0 + std::sin(u));
  }
  double unbounded(size_t j, double p) const
  {
    const auto &q = parameters_[j];
    return std::asin(std::clamp(2.0 * (p - q.low) / (q.high - q.low) - 1.0, -0.999, 0.999));
  }

  std::vector<Pole> layout(const Eigen::VectorXd &u) const
  {
    std::vector<Pole> p = base_;
    for (size_t j = 0; j < parameters_.size(); ++j)
      set(p, parameters_[j], physical(j, u(j)));
    return p;
  }
  Eigen::VectorXd start(const std::vector<Pole> &poles) const
  {
    Eigen::VectorXd u(inputs());
    for (size_t j = 0; j < parameters_.size(); ++j)
      u(j) = unbounded(j, get(poles, parameters_[j]));
    return u;
  }

  static double get(const std::vector<Pole> &p, const DesignParameter &q)
  {
    return q.angle ? p[q.pole].angle : std::abs(p[q.pole].strength);
  }
  static void set(std::vector<Pole> &p, const DesignParameter &q, double v)
  {
    if (q.angle)
      p[q.pole].angle = v;
    else
      p[q.pole].strength = std::copysign(v, p[q.pole].strength);
  }

  // The requirements' residuals of a layout (no regularisation).
  std::vector<double> requirement_residuals(const std::vector<Pole> &poles) const
  {
    return RequirementSet::stacked_residuals(requirements_->evaluate(poles, ring_->of(poles)));
  }

  int operator()(const Eigen::VectorXd &u, Eigen::VectorXd &f) const
  {
    const auto poles = layout(u);
    const auto r = requirement_residuals(poles);
    f.resize(values());
    for (size_t k = 0; k < r.size(); ++k)
      f(k) = r[k];
    for (size_t j = 0; j < parameters_.size(); ++j)
    {
      const auto &q = parameters_[j];
      const double scale = q.angle ? deg : 0.01 * std::abs(base_[q.pole].strength);
      f(m_requirements_ + j) = lambda_ * (get(poles, q) - get(base_, q)) / scale;
    }
    ++*evaluations;
    return 0;
  }

  std::shared_ptr<long> evaluations = std::make_shared<long>(0); // shared by NumericalDiff's copies

private:
  const RingProfile *ring_;
  const RequirementSet *requirements_;
  std::vector<Pole> base_;
  std::vector<DesignParameter> parameters_;
  double lambda_;
  size_t m_requirements_ = 0;
};

double sum_of_squares(const std::vector<double> &r)
{
  double s = 0;
  for (double x : r)
    s += x * x;
  return s;
}

// The starts: the case's layout (inside its boxes), then layouts drawn uniformly in them.
std::vector<std::vector<Pole>> starting_layouts(const std::vector<Pole> &base,
                                                const std::vector<DesignParameter> &parameters,
                                                const DesignOptions &options)
{
  std::vector<std::vector<Pole>> starts = {base};
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int s = 1; s < options.starts; ++s)
  {
    auto p = base;
    for (const auto &q : parameters)
      DesignFunctor::set(p, q, q.low + (q.high - q.low) * unit(rng));
    starts.push_back(p);
  }
  return starts;
}

std::string status_in_words(Eigen::LevenbergMarquardtSpace::Status s)
{
  using namespace Eigen::LevenbergMarquardtSpace;
  switch (s)
  {
  case RelativeReductionTooSmall: return "converged (sum of squares settled)";
  case RelativeErrorTooSmall: return "converged (parameters settled)";
  case RelativeErrorAndReductionTooSmall: return "converged (parameters and sum of squares settled)";
  case CosinusTooSmall: return "converged (residual orthogonal to the Jacobian)";
  case TooManyFunctionEvaluation: return "stopped: too many evaluations";
  case FtolTooSmall: return "converged (no further reduction possible)";
  case XtolTooSmall: return "converged (no further improvement possible)";
  case GtolTooSmall: return "stopped: gtol too small";
  default: return "stopped (status " + std::to_string(int(s)) + ")";
  }
}

// What binds: parameters at a bound that the cost pushes against, fixed poles that would move,
// the minimum spacing at its limit.
std::vector<std::string> binding_constraints(const DesignFunctor &problem, const DesignResult &r,
                                             const std::vector<PoleLimits> &limits,
                                             const DesignTarget &target)
{
  std::vector<std::pair<double, std::string>> found; // (cost fall per unit move, words)
  const double c0 = sum_of_squares(problem.requirement_residuals(r.poles));
  // per degree or per 10 kA/m; a cost of 1 is one requirement at the edge of its tolerance
  const double negligible = std::max(1e-3 * c0, 1e-3);
  auto cost_moved = [&](size_t pole, bool angle, double by) {
    auto p = r.poles;
    DesignFunctor::set(p, {pole, angle}, DesignFunctor::get(p, {pole, angle}) + by);
    return sum_of_squares(problem.requirement_residuals(p));
  };
  for (const auto &q : r.parameters)
  {
    double v = DesignFunctor::get(r.poles, q);
    if (q.angle) // the layout's angles are wrapped, the boxes unwrapped around the case's
      v = q.low + wrap_0_2pi(v - q.low + 1e-9) - 1e-9;
    const double span = q.high - q.low;
    const bool at_high = v > q.high - 1e-3 * span, at_low = v < q.low + 1e-3 * span;
    if (!at_high && !at_low)
      continue;
    const double step = q.angle ? 0.01 * deg : 1e-3 * std::abs(r.poles[q.pole].strength);
    const double rate = (c0 - cost_moved(q.pole, q.angle, at_high ? step : -step)) / step;
    const double per_unit = rate * (q.angle ? deg : 1e4);
    if (!(per_unit > negligible))
      continue;
    const std::string bound = at_high ? (q.high_is_remanence_limit ? "the remanence limit (max_strength)" : "its upper bound")
                                      : "its lower bound";
    found.emplace_back(per_unit, q.name(r.poles) + " at " + bound + " " +
                  (q.angle ? f2(wrap_0_2pi(v) / deg) + "°" : f2(v * 1e-3) + " kA/m") +
                  ": the cost " + f2(c0) + " would fall by " +
                  (q.angle ? f2(rate * deg) + " per degree" : f2(rate * 1e4) + " per 10 kA/m") + " beyond it");
  }
  for (size_t i = 0; i < limits.size(); ++i)
  {
    if (!limits[i].fixed)
      continue;
    for (bool angle : {true, false})
    {
      const double step = angle ? 0.01 * deg : 1e-3 * std::abs(r.poles[i].strength);
      const double rate = (cost_moved(i, angle, -step) - cost_moved(i, angle, step)) / (2 * step);
      const double per_unit = std::abs(rate) * (angle ? deg : 1e4);
      if (per_unit > negligible)
        found.emplace_back(per_unit, r.poles[i].name + " is fixed: " + (angle ? "turning it " : "making it ") +
                      (angle ? (rate > 0 ? "counter-clockwise" : "clockwise") : (rate > 0 ? "stronger" : "weaker")) +
                      " would lower the cost by " + f2(std::abs(rate) * (angle ? deg : 1e4)) +
                      (angle ? " per degree" : " per 10 kA/m"));
    }
  }
  // The strongest first.
  std::stable_sort(found.begin(), found.end(), [](const auto &a, const auto &b) { return a.first > b.first; });
  std::vector<std::string> out;
  for (const auto &f : found)
    out.push_back(f.second);
  for (const auto &req : r.requirements)
    if (req.kind == RequirementResult::Kind::at_least && target.min_spacing > 0 &&
        req.value < req.target + 0.05)
      out.push_back("the minimum spacing " + f2(req.target) + "° (" + req.detail + " at " + f2(req.value) + "°)");
  return out;
}

} // namespace

std::string DesignParameter::name(const std::vector<Pole> &poles) const
{
  return poles[pole].name + (angle ? " angle" : " |M|");
}

DesignResult design_poles(const Roller &roller, double probe_radius, const DesignTarget &target,
                          const DesignConstraints &constraints, const DesignOptions &options)
{
  if (roller.poles.empty())
    throw std::invalid_argument("the case's roller has no poles to design");
  const RingProfile ring(roller, probe_radius);
  const RequirementSet requirements(target, roller);
  const auto limits = constraints.limits_for(roller.poles);
  DesignResult result;
  result.harmonics = ring.harmonics();
  result.parameters = free_parameters(roller.poles, limits, constraints.max_strength);
  // The base layout: the case's, moved inside its boxes.
  std::vector<Pole> base = roller.poles;
  for (const auto &q : result.parameters)
    DesignFunctor::set(base, q, std::clamp(DesignFunctor::get(base, q), q.low, q.high));
  const DesignFunctor problem(ring, requirements, base, result.parameters, options.regularisation);

  double best = std::numeric_limits<double>::infinity();
  std::vector<Pole> best_poles = base;
  if (!result.parameters.empty())
  {
    if (problem.values() < problem.inputs())
      throw std::invalid_argument("internal: fewer residuals than unknowns");
    const auto starts = starting_layouts(base, result.parameters, options);
    for (size_t s = 0; s < starts.size(); ++s)
    {
      Eigen::NumericalDiff<DesignFunctor, Eigen::Central> numeric(problem);
      Eigen::LevenbergMarquardt<decltype(numeric)> lm(numeric);
      lm.parameters.maxfev = options.max_evaluations;
      lm.parameters.xtol = 1e-12;
      lm.parameters.ftol = 1e-14;
      Eigen::VectorXd u = problem.start(starts[s]);
      const auto status = lm.minimize(u);
      const auto poles = problem.layout(u);
      const double cost = sum_of_squares(problem.requirement_residuals(poles));
      result.start_costs.push_back(cost);
      if (cost < best)
      {
        best = cost;
        best_poles = poles;
        result.best_start = int(s);
        result.status = status_in_words(status);
      }
    }
  }
  else
  {
    best = sum_of_squares(problem.requirement_residuals(base));
    result.status = "nothing to vary: every pole is fixed";
  }
  for (auto &p : best_poles)
    p.angle = wrap_0_2pi(p.angle);
  result.poles = best_poles;
  result.cost = best;
  for (double c : result.start_costs)
    result.starts_at_best += c <= best * (1 + 1e-6) + 1e-12;
  result.requirements = requirements.evaluate(result.poles, ring.of(result.poles));
  result.feasible = std::all_of(result.requirements.begin(), result.requirements.end(),
                                [](const RequirementResult &r) { return r.met(); });
  result.binding = binding_constraints(problem, result, limits, target);
  result.evaluations = *problem.evaluations;
  return result;
}

} // namespace magbrush
