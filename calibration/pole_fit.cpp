// Pole fitting by Levenberg–Marquardt on the exact ring (see pole_fit.h).
#include "calibration/pole_fit.h"

#include "calibration/shape_selection.h"

#include <Eigen/Dense>
#include <unsupported/Eigen/NonLinearOptimization>

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <sstream>
#include <stdexcept>

namespace magbrush {

namespace {

constexpr double mu0 = 4e-7 * M_PI;
constexpr double pi = M_PI;

double wrap_pm_pi(double a)
{
  a = std::remainder(a, 2.0 * pi);
  return a <= -pi ? a + 2.0 * pi : a;
}

double wrap_0_2pi(double a)
{
  a = std::fmod(a, 2.0 * pi);
  return a < 0 ? a + 2.0 * pi : a;
}

std::string status_in_words(Eigen::LevenbergMarquardtSpace::Status s)
{
  using namespace Eigen::LevenbergMarquardtSpace;
  switch (s)
  {
  case RelativeReductionTooSmall: return "converged (relative reduction of the sum of squares below ftol)";
  case RelativeErrorTooSmall: return "converged (relative change of the parameters below xtol)";
  case RelativeErrorAndReductionTooSmall: return "converged (parameters and sum of squares both settled)";
  case CosinusTooSmall: return "converged (residual orthogonal to the Jacobian)";
  case TooManyFunctionEvaluation: return "stopped: too many function evaluations";
  case FtolTooSmall: return "stopped: ftol too small, no further reduction possible";
  case XtolTooSmall: return "stopped: xtol too small, no further improvement possible";
  case GtolTooSmall: return "stopped: gtol too small";
  case ImproperInputParameters: return "failed: improper input parameters";
  default: return "stopped (status " + std::to_string(int(s)) + ")";
  }
}

bool converged(Eigen::LevenbergMarquardtSpace::Status s)
{
  using namespace Eigen::LevenbergMarquardtSpace;
  return s == RelativeReductionTooSmall || s == RelativeErrorTooSmall ||
         s == RelativeErrorAndReductionTooSmall || s == CosinusTooSmall || s == FtolTooSmall ||
         s == XtolTooSmall;
}

} // namespace

// ---------------------------------------------------------------------------------------
// Forward model

PoleProfileModel::PoleProfileModel(const RingGeometry &geometry, double probe_radius, int harmonics)
{
  geometry.validate();
  if (!(probe_radius >= geometry.magnet_radius))
  {
    std::ostringstream msg;
    msg << "the probe radius " << probe_radius * 1e3 << " mm lies inside the magnet (outer radius "
        << geometry.magnet_radius * 1e3
        << " mm); a gaussmeter scans outside it: set field.probe_radius ≥ the magnet radius "
           "(0 = the sleeve radius)";
    throw std::invalid_argument(msg.str());
  }
  if (harmonics < 1)
    throw std::invalid_argument("pole model: need at least one harmonic");
  exterior_.assign(harmonics + 1, 0.0);
  for (int n = 1; n <= harmonics; ++n)
    exterior_[n] = mu0 * MultipoleRing::HarmonicResponse(geometry, n).exterior_factor(probe_radius);
  samples_ = GaussianPoleSpectrum::default_samples(harmonics);
}

GaussianPoleSpectrum PoleProfileModel::spectrum(double alpha) const
{
  return GaussianPoleSpectrum::compute(alpha, harmonics(), samples_);
}

PoleProfileModel::PoleTerms PoleProfileModel::terms(double alpha, double angle,
                                                    const std::vector<double> &theta,
                                                    bool derivatives) const
{
  return terms(spectrum(alpha), angle, theta, derivatives);
}

PoleProfileModel::PoleTerms PoleProfileModel::terms(const GaussianPoleSpectrum &spectrum,
                                                    double angle, const std::vector<double> &theta,
                                                    bool derivatives) const
{
  const int N = harmonics();
  std::vector<double> w(N + 1), wa(N + 1);
  for (int n = 1; n <= N; ++n)
  {
    w[n] = exterior_[n] * spectrum.g[n];
    wa[n] = exterior_[n] * spectrum.dg_da[n];
  }
  const size_t m = theta.size();
  PoleTerms t;
  t.C.assign(m, 0.0);
  t.S.assign(m, 0.0);
  if (derivatives)
  {
    t.nC.assign(m, 0.0);
    t.nS.assign(m, 0.0);
    t.Ca.assign(m, 0.0);
    t.Sa.assign(m, 0.0);
  }
  for (size_t k = 0; k < m; ++k)
  {
    const double u = theta[k] - angle;
    const std::complex<double> step(std::cos(u), std::sin(u));
    std::complex<double> z(1.0, 0.0);
    double C = 0, S = 0, nC = 0, nS = 0, Ca = 0, Sa = 0;
    for (int n = 1; n <= N; ++n)
    {
      z *= step; // e^{inu}
      C += w[n] * z.real();
      S += w[n] * z.imag();
      if (derivatives)
      {
        nC += n * w[n] * z.real();
        nS += n * w[n] * z.imag();
        Ca += wa[n] * z.real();
        Sa += wa[n] * z.imag();
      }
    }
    t.C[k] = C;
    t.S[k] = S;
    if (derivatives)
    {
      t.nC[k] = nC;
      t.nS[k] = nS;
      t.Ca[k] = Ca;
      t.Sa[k] = Sa;
    }
  }
  return t;
}

void PoleProfileModel::profile(const std::vector<Pole> &poles, const std::vector<double> &theta,
                               std::vector<double> &Bn, std::vector<double> &Bt) const
{
  Bn.assign(theta.size(), 0.0);
  Bt.assign(theta.size(), 0.0);
  for (const Pole &p : poles)
  {
    const auto t = terms(p.shape_factor, p.angle, theta, false);
    for (size_t k = 0; k < theta.size(); ++k)
    {
      Bn[k] += p.strength * t.C[k];
      Bt[k] += p.strength * t.S[k];
    }
  }
}

// ---------------------------------------------------------------------------------------
// The least-squares problem

namespace {

// Parameter vector x = [M_i / M_scale (P) | angle deviations a (P−1 with offset, P without)
//                       | ln α (0, 1 or P) | δ (1 with offset)].
// φ = base + T a, where T spreads the constraint Σ(φ − φ_nominal) = 0 (see pole_fit.h).
class FitProblem
{
public:
  FitProblem(const PoleProfileModel &model, const FluxScan &scan, const std::vector<Pole> &base,
             const PoleFitOptions &options, double strength_scale)
      : model_(model), scan_(scan), base_(base), options_(options), scale_(strength_scale)
  {
    P_ = base.size();
    n_angle_ = options.fit_offset ? P_ - 1 : P_;
    n_shape_ = options.shape == PoleFitOptions::Shape::fixed ? 0
               : options.shape == PoleFitOptions::Shape::shared ? 1
                                                                : P_;
    n_offset_ = options.fit_offset ? 1 : 0;
    use_bt_ = options.use_tangential && scan.has_tangential();
    m_ = scan.size() * (use_bt_ ? 2 : 1);
    T_ = Eigen::MatrixXd::Zero(P_, n_angle_);
    for (size_t j = 0; j < n_angle_; ++j)
    {
      T_(j, j) = 1.0;
      if (options.fit_offset)
        T_(P_ - 1, j) = -1.0;
    }
  }

  // Eigen's functor interface.
  int inputs() const { return static_cast<int>(P_ + n_angle_ + n_shape_ + n_offset_); }
  int values() const { return static_cast<int>(m_); }
  int operator()(const Eigen::VectorXd &x, Eigen::VectorXd &f) const
  {
    evaluate(x, f, nullptr);
    ++evaluations;
    return 0;
  }
  int df(const Eigen::VectorXd &x, Eigen::MatrixXd &J) const
  {
    Eigen::VectorXd f(m_);
    evaluate(x, f, &J);
    return 0;
  }

  std::vector<Pole> poles(const Eigen::VectorXd &x) const
  {
    std::vector<Pole> p = base_;
    const Eigen::VectorXd phi = T_ * x.segment(P_, n_angle_);
    for (size_t i = 0; i < P_; ++i)
    {
      p[i].strength = scale_ * x(i);
      p[i].angle = base_[i].angle + phi(i);
      if (n_shape_ == 1)
        p[i].shape_factor = std::exp(x(P_ + n_angle_));
      else if (n_shape_ == P_)
        p[i].shape_factor = std::exp(x(P_ + n_angle_ + i));
    }
    return p;
  }
  double offset(const Eigen::VectorXd &x) const { return n_offset_ ? x(x.size() - 1) : 0.0; }

  Eigen::VectorXd pack(const std::vector<Pole> &poles, const std::vector<double> &deviation,
                       double offset) const
  {
    Eigen::VectorXd x(inputs());
    for (size_t i = 0; i < P_; ++i)
      x(i) = poles[i].strength / scale_;
    for (size_t j = 0; j < n_angle_; ++j)
      x(P_ + j) = deviation[j];
    if (n_shape_ == 1) // one α for all: start from the geometric mean of the given ones
    {
      double log_mean = 0.0;
      for (const Pole &p : poles)
        log_mean += std::log(p.shape_factor) / poles.size();
      x(P_ + n_angle_) = log_mean;
    }
    else
      for (size_t i = 0; i < n_shape_; ++i)
        x(P_ + n_angle_ + i) = std::log(poles[i].shape_factor);
    if (n_offset_)
      x(x.size() - 1) = offset;
    return x;
  }

  size_t P_, n_angle_, n_shape_, n_offset_, m_;
  bool use_bt_;
  Eigen::MatrixXd T_;
  mutable int evaluations = 0;

private:
  const PoleProfileModel &model_;
  const FluxScan &scan_;
  std::vector<Pole> base_;
  PoleFitOptions options_;
  double scale_;

  void evaluate(const Eigen::VectorXd &x, Eigen::VectorXd &f, Eigen::MatrixXd *J) const
  {
    const auto p = poles(x);
    const double delta = offset(x);
    const size_t m = scan_.size();
    std::vector<double> theta(m);
    for (size_t k = 0; k < m; ++k)
      theta[k] = scan_.angle[k] + delta;
    f.setZero(m_);
    if (J)
      J->setZero(m_, inputs());
    const size_t bt_row = m; // Bt residuals follow the Bn ones
    for (size_t i = 0; i < P_; ++i)
    {
      const auto t = model_.terms(p[i].shape_factor, p[i].angle, theta, J != nullptr);
      const double M = p[i].strength;
      for (size_t k = 0; k < m; ++k)
      {
        f(k) += M * t.C[k];
        if (use_bt_)
          f(bt_row + k) += M * t.S[k];
      }
      if (!J)
        continue;
      for (size_t k = 0; k < m; ++k)
      {
        // ∂/∂M_i, ∂/∂φ_i (through T), ∂/∂ln α, ∂/∂δ
        (*J)(k, i) = scale_ * t.C[k];
        const double dphi_n = M * t.nS[k];
        for (size_t j = 0; j < n_angle_; ++j)
          (*J)(k, P_ + j) += T_(i, j) * dphi_n;
        if (n_shape_)
          (*J)(k, P_ + n_angle_ + (n_shape_ == 1 ? 0 : i)) += M * p[i].shape_factor * t.Ca[k];
        if (n_offset_)
          (*J)(k, inputs() - 1) -= M * t.nS[k];
        if (!use_bt_)
          continue;
        const size_t r = bt_row + k;
        (*J)(r, i) = scale_ * t.S[k];
        const double dphi_t = -M * t.nC[k];
        for (size_t j = 0; j < n_angle_; ++j)
          (*J)(r, P_ + j) += T_(i, j) * dphi_t;
        if (n_shape_)
          (*J)(r, P_ + n_angle_ + (n_shape_ == 1 ? 0 : i)) += M * p[i].shape_factor * t.Sa[k];
        if (n_offset_)
          (*J)(r, inputs() - 1) += M * t.nC[k];
      }
    }
    for (size_t k = 0; k < m; ++k)
    {
      f(k) -= scan_.Bn[k];
      if (use_bt_)
        f(bt_row + k) -= scan_.Bt[k];
    }
  }
};

int harmonics_for_fit(const std::vector<Pole> &poles, const PoleFitOptions &options)
{
  if (options.harmonics > 0)
    return options.harmonics;
  // The fit may sharpen the poles: size the series for 4× the largest initial α, so the
  // forward model stays exact (coefficients below 1e-12 of the largest) along the way.
  double alpha = 0.0;
  for (const Pole &p : poles)
    alpha = std::max(alpha, p.shape_factor);
  return static_cast<int>(std::ceil(2.0 * std::sqrt(4.0 * alpha * std::log(1e12)))) + 4;
}

void check_starting_poles(const Roller &nominal)
{
  if (nominal.poles.empty())
    throw std::invalid_argument("pole fit: the case has no poles to start from; add roller.poles "
                                "with approximate angles and signs");
  for (const Pole &p : nominal.poles)
    if (!(p.shape_factor > 0.0) || p.strength == 0.0)
      throw std::invalid_argument("pole fit: pole '" + p.name +
                                  "' needs a non-zero strength (its sign says N or S) and a "
                                  "positive shape factor as a starting point");
}

// The starting point of the fit: angles from the scan's peaks, strengths by linear least squares.
struct InitialGuess
{
  std::vector<Pole> poles;
  std::vector<double> deviation; // φ_i − φ_i^nominal
  double offset = 0.0;           // δ
};

// Each pole is moved by the shift between its measured and computed Bn peak (the peak of a
// pole is not exactly at φ_i, its neighbours pull it, so the shift is taken between profiles,
// not against φ_i). With the offset fitted, the common part of the shifts is δ:
// p_i + δ = c_i + Δ_i with ΣΔ_i = 0.
void place_poles_at_the_peaks(const PoleProfileModel &model, const Roller &nominal,
                              const FluxScan &scan, const PoleFitOptions &options,
                              InitialGuess &guess, std::vector<std::string> &notes)
{
  const size_t P = nominal.poles.size();
  std::vector<double> Bn0, Bt0;
  model.profile(nominal.poles, scan.angle, Bn0, Bt0);
  const auto measured = find_pole_peaks(nominal.poles, scan.angle, scan.Bn);
  const auto computed = find_pole_peaks(nominal.poles, scan.angle, Bn0);
  std::vector<double> shift(P, 0.0); // measured − computed peak angle
  std::vector<bool> matched(P, false);
  double mean_shift = 0.0;
  size_t n_matched = 0;
  for (size_t i = 0; i < P; ++i)
    if (measured[i].found && computed[i].found)
    {
      shift[i] = wrap_pm_pi(measured[i].angle - computed[i].angle);
      matched[i] = true;
      mean_shift += shift[i];
      ++n_matched;
    }
    else
      notes.push_back("pole " + nominal.poles[i].name +
                      ": no matching Bn peak in the scan; starting from its nominal angle");
  if (n_matched)
    mean_shift /= n_matched;
  guess.deviation.assign(P, 0.0);
  guess.offset = 0.0;
  if (options.fit_offset)
  {
    guess.offset = -mean_shift;
    for (size_t i = 0; i < P; ++i)
      guess.deviation[i] = matched[i] ? shift[i] + guess.offset : 0.0;
    double mean = 0.0;
    for (double d : guess.deviation)
      mean += d / P;
    for (double &d : guess.deviation)
      d -= mean;
  }
  else
    guess.deviation = shift;
  guess.poles = nominal.poles;
  for (size_t i = 0; i < P; ++i)
    guess.poles[i].angle = nominal.poles[i].angle + guess.deviation[i];
}

// With the angles and shapes fixed the model is linear in the strengths: the exact linear
// least-squares solution for them.
void solve_for_strengths(const PoleProfileModel &model, const FluxScan &scan, bool use_bt,
                         InitialGuess &guess, const Roller &nominal, std::vector<std::string> &notes)
{
  const size_t P = guess.poles.size(), m = scan.size();
  std::vector<double> theta(m);
  for (size_t k = 0; k < m; ++k)
    theta[k] = scan.angle[k] + guess.offset;
  Eigen::MatrixXd A(use_bt ? 2 * m : m, P);
  Eigen::VectorXd b(A.rows());
  for (size_t i = 0; i < P; ++i)
  {
    const auto t = model.terms(guess.poles[i].shape_factor, guess.poles[i].angle, theta, false);
    for (size_t k = 0; k < m; ++k)
    {
      A(k, i) = t.C[k];
      if (use_bt)
        A(m + k, i) = t.S[k];
    }
  }
  for (size_t k = 0; k < m; ++k)
  {
    b(k) = scan.Bn[k];
    if (use_bt)
      b(m + k) = scan.Bt[k];
  }
  const Eigen::VectorXd M = A.colPivHouseholderQr().solve(b);
  for (size_t i = 0; i < P; ++i)
  {
    if (M(i) * nominal.poles[i].strength <= 0.0)
      notes.push_back("pole " + nominal.poles[i].name +
                      ": the scan suggests the opposite sign; check the pole order");
    guess.poles[i].strength = M(i);
  }
}

// Residual RMS per component and the standard errors from the Jacobian at the optimum:
// Cov = s² (JᵀJ)⁻¹, s² = RSS/(m − p), mapped to the physical parameters.
void summarise(const FitProblem &problem, const Eigen::VectorXd &x, double strength_scale,
               const Roller &nominal, const InitialGuess &guess, PoleFitResult &result)
{
  const size_t P = nominal.poles.size();
  const size_t m = problem.use_bt_ ? problem.m_ / 2 : problem.m_;
  Eigen::VectorXd f(problem.values());
  Eigen::MatrixXd J(problem.values(), problem.inputs());
  problem(x, f);
  problem.df(x, J);
  result.rms_Bn = std::sqrt(f.head(m).squaredNorm() / m);
  result.rms_Bt = problem.use_bt_ ? std::sqrt(f.tail(m).squaredNorm() / m) : 0.0;
  result.rms = std::sqrt(f.squaredNorm() / f.size());
  const double s2 = f.squaredNorm() / double(problem.values() - problem.inputs());
  const Eigen::MatrixXd JtJ = J.transpose() * J;
  const Eigen::MatrixXd cov =
      s2 * JtJ.ldlt().solve(Eigen::MatrixXd::Identity(JtJ.rows(), JtJ.cols()));
  const Eigen::MatrixXd Caa = cov.block(P, P, problem.n_angle_, problem.n_angle_);
  const Eigen::MatrixXd Cphi = problem.T_ * Caa * problem.T_.transpose();
  const auto poles = problem.poles(x);
  result.offset = problem.offset(x);
  result.offset_sigma = problem.n_offset_ ? std::sqrt(cov(x.size() - 1, x.size() - 1)) : 0.0;
  result.roller = nominal;
  for (size_t i = 0; i < P; ++i)
  {
    FittedPole fp;
    fp.pole = poles[i];
    fp.pole.angle = wrap_0_2pi(poles[i].angle);
    fp.initial = guess.poles[i];
    fp.initial.angle = wrap_0_2pi(guess.poles[i].angle);
    fp.strength_sigma = strength_scale * std::sqrt(cov(i, i));
    fp.angle_sigma = std::sqrt(std::max(0.0, Cphi(i, i)));
    if (problem.n_shape_)
    {
      const size_t j = P + problem.n_angle_ + (problem.n_shape_ == 1 ? 0 : i);
      fp.shape_sigma = poles[i].shape_factor * std::sqrt(cov(j, j));
    }
    result.poles.push_back(fp);
    result.roller.poles[i] = fp.pole;
  }
  double alpha_max = 0.0;
  for (const Pole &p : poles)
    alpha_max = std::max(alpha_max, p.shape_factor);
  if (2.0 * std::sqrt(alpha_max * std::log(1e12)) > result.harmonics)
    result.notes.push_back("the fitted shape factors are sharper than the series was sized for; "
                           "rerun with more harmonics");
}

// The scan's noise (scan_noise.h) over the components the fit used, in the same measure as
// the residual RMS: the RMS of the per-component noise over all fitted values.
void estimate_noise_of_fitted_values(const FluxScan &scan, bool used_bt, PoleFitResult &result)
{
  result.noise = estimate_scan_noise(scan);
  result.noise_rms = used_bt ? std::sqrt(0.5 * (result.noise.Bn * result.noise.Bn +
                                                result.noise.Bt * result.noise.Bt))
                             : result.noise.Bn;
}

} // namespace

PoleFitResult fit_poles(const Roller &nominal, const FluxScan &scan, double probe_radius,
                        const PoleFitOptions &options)
{
  if (options.shape == PoleFitOptions::Shape::automatic)
    return fit_poles_choosing_shape(nominal, scan, probe_radius, options);
  check_starting_poles(nominal);
  PoleFitResult result;
  result.shape = options.shape;
  result.harmonics = harmonics_for_fit(nominal.poles, options);
  const PoleProfileModel model(RingGeometry::from(nominal), probe_radius, result.harmonics);

  InitialGuess guess;
  place_poles_at_the_peaks(model, nominal, scan, options, guess, result.notes);
  solve_for_strengths(model, scan, options.use_tangential && scan.has_tangential(), guess, nominal,
                      result.notes);

  // Angles are parametrised relative to the nominal layout when the offset is fitted (that is
  // the constraint), else relative to the initial guess.
  const size_t P = nominal.poles.size();
  std::vector<Pole> base = options.fit_offset ? nominal.poles : guess.poles;
  std::vector<double> a0(P, 0.0);
  if (options.fit_offset)
    for (size_t i = 0; i + 1 < P; ++i)
      a0[i] = guess.deviation[i];
  double scale = 0.0;
  for (const Pole &p : guess.poles)
    scale = std::max(scale, std::abs(p.strength));
  FitProblem problem(model, scan, base, options, scale);
  result.parameters = problem.inputs();
  result.samples = problem.values();
  if (result.samples <= result.parameters)
    throw std::invalid_argument("pole fit: " + std::to_string(result.samples) +
                                " residuals for " + std::to_string(result.parameters) +
                                " parameters; the scan needs more points");
  Eigen::VectorXd x = problem.pack(guess.poles, a0, guess.offset);
  {
    Eigen::VectorXd f(problem.values());
    problem(x, f);
    result.initial_rms = std::sqrt(f.squaredNorm() / f.size());
  }

  Eigen::LevenbergMarquardt<FitProblem> lm(problem);
  lm.parameters.maxfev = options.max_evaluations;
  lm.parameters.xtol = 1e-12;
  lm.parameters.ftol = 1e-14;
  const auto status = lm.minimize(x);
  result.status = status_in_words(status);
  result.converged = converged(status);
  result.evaluations = problem.evaluations;
  result.iterations = static_cast<int>(lm.iter);

  summarise(problem, x, scale, nominal, guess, result);
  estimate_noise_of_fitted_values(scan, problem.use_bt_, result);
  return result;
}

FluxComparison compare_with_fitted_model(const FluxScan &scan, const PoleFitResult &fit,
                                         double probe_radius,
                                         const MultipoleRing::Options &ring_options)
{
  const FluxScan aligned = rotated_scan(scan, fit.offset);
  std::vector<double> Bn, Bt;
  MultipoleRing(fit.roller, ring_options).profile(probe_radius, aligned.angle, Bn, Bt);
  return compare_flux(aligned, Bn, Bt, fit.roller.poles);
}

std::string residual_warning(const PoleFitResult &fit)
{
  if (!(fit.noise_rms > 0.0) || fit.rms <= residual_far_above_noise * fit.noise_rms)
    return "";
  std::ostringstream out;
  out.precision(3);
  out << "the residual RMS " << fit.rms * 1e3 << " mT is " << fit.rms / fit.noise_rms
      << " times the noise estimated from the scan (" << fit.noise_rms * 1e3
      << " mT): the pole model does not describe this scan, and the uncertainties above are "
         "too small. Try: ";
  if (fit.shape != PoleFitOptions::Shape::per_pole)
    out << "one shape factor per pole (--fit-shape per-pole); ";
  out << "the case's number, order and signs of the poles; the roller geometry (magnet and "
         "shaft radii) and field.probe_radius; the scan's direction and sign conventions "
         "(--clockwise, --flip-bt) and units; the residual plot, for a pole or feature the "
         "model lacks";
  return out.str();
}

std::string shape_name(PoleFitOptions::Shape shape)
{
  switch (shape)
  {
  case PoleFitOptions::Shape::fixed: return "fixed";
  case PoleFitOptions::Shape::shared: return "shared";
  case PoleFitOptions::Shape::per_pole: return "per-pole";
  case PoleFitOptions::Shape::automatic: return "auto";
  }
  return "?";
}

} // namespace magbrush
