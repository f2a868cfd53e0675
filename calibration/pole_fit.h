// Calibrating the Gaussian pole model to a gaussmeter scan: nonlinear least squares
// (Levenberg–Marquardt, Eigen's unsupported module, analytic Jacobian) with the exact
// multipole ring as the forward model.
//
// Unknowns: per pole the strength M_i and the angle φ_i; the shape factors α (one shared or
// one per pole, fitted as ln α so that they stay positive — a shared one starts from the
// geometric mean of the case's values —, or held fixed); and the encoder
// offset δ of the scan (model evaluated at θ_scan + δ).
//
// The offset and a common rotation of all poles are the same thing to a scan, so only their
// combination is observable. We define the encoder offset as the common rotation between the
// scan and the nominal (case) pole layout: the fitted pole angles are constrained to deviate
// from the nominal ones by zero on average, Σ(φ_i − φ_i^nominal) = 0, and the common part is δ.
// With `fit_offset = false`, δ = 0 and every angle is free.
//
// The initial guess comes from the scan itself: each nominal pole is matched to the measured
// Bn extremum of its sign nearest its nominal angle, which fixes the angles (and δ); with those
// angles and the nominal shapes the model is linear in the strengths, which are then the exact
// linear least-squares solution. LM starts from there.
//
// Uncertainties are the standard errors from the Jacobian at the optimum,
// Cov = s² (JᵀJ)⁻¹ with s² = RSS/(m − p), mapped to the physical parameters.
//
// The shape model can be chosen from the data (Shape::automatic, see shape_selection.h): one
// shared α, or one per pole when that lowers the residual significantly. Every fit also
// estimates the scan's noise from the scan itself (scan_noise.h) and says plainly when the
// residual stays far above it: then the model does not describe the scan, whatever the
// uncertainties say.
#pragma once

#include "calibration/flux_compare.h"
#include "calibration/flux_scan.h"
#include "calibration/nested_model_test.h"
#include "calibration/scan_noise.h"
#include "case/case_model.h"
#include "fields/multipole_ring.h"

#include <string>
#include <vector>

namespace magbrush {

struct PoleFitOptions
{
  // fixed: the case's α; shared: one α for all poles; per_pole: one each; automatic: shared,
  // or per_pole when the F-test says it fits significantly better (shape_selection.h).
  enum class Shape { fixed, shared, per_pole, automatic } shape = Shape::automatic;
  double shape_significance = 0.001; // automatic: per_pole when the F-test's p-value is below
  bool fit_offset = true;
  bool use_tangential = true;   // fit Bt too when the scan has it
  int harmonics = 0;            // 0 = enough for 4× the largest initial α (relative 1e-12)
  int max_evaluations = 4000;
};

struct FittedPole
{
  Pole pole;                    // fitted values (angle in the roller frame, wrapped to [0, 2π))
  double strength_sigma = 0.0;  // [A/m]
  double angle_sigma = 0.0;     // [rad]
  double shape_sigma = 0.0;     // [1/rad²] (0 when fixed)
  Pole initial;                 // the initial guess from the scan
};

// How Shape::automatic chose between one shared α and one α per pole.
struct ShapeSelection
{
  bool automatic = false;                    // false: the shape model was given
  double rms_shared = 0.0, rms_per_pole = 0.0; // residual RMS of both fits [T]
  NestedModelTest test;                      // per-pole against shared
  double significance = 0.0;                 // per-pole kept when test.p_value < this
  std::string reason;                        // the verdict in words
};

struct PoleFitResult
{
  Roller roller;                // the case's roller with the fitted poles
  std::vector<FittedPole> poles;
  double offset = 0.0, offset_sigma = 0.0; // encoder offset δ [rad]
  double rms_Bn = 0.0, rms_Bt = 0.0, rms = 0.0; // residual RMS [T] (rms: both components)
  double initial_rms = 0.0;     // RMS at the initial guess
  int evaluations = 0, iterations = 0;
  int harmonics = 0;
  size_t samples = 0, parameters = 0;
  bool converged = false;
  std::string status;           // LM's verdict in words
  PoleFitOptions::Shape shape = PoleFitOptions::Shape::shared; // the shape model fitted
  ShapeSelection shape_selection;
  ScanNoise noise;              // estimated from the scan itself (scan_noise.h)
  double noise_rms = 0.0;       // that noise over the fitted components, comparable with rms [T]
  std::vector<std::string> notes;
};

// The fast forward model: Bn, Bt at the probe radius (outside the magnet) for given poles,
// with derivatives. Evaluates Σ_n e_n g_n(α) cos/sin n(θ − φ) with precomputed e_n.
class PoleProfileModel
{
public:
  PoleProfileModel(const RingGeometry &geometry, double probe_radius, int harmonics);
  int harmonics() const { return static_cast<int>(exterior_.size()) - 1; }

  // Per pole i and angle k: the unit-strength profile and its derivatives.
  struct PoleTerms
  {
    std::vector<double> C, S;        // Bn, Bt of unit strength [T per A/m]
    std::vector<double> nC, nS;      // Σ n e_n g_n cos/sin (for ∂/∂θ)
    std::vector<double> Ca, Sa;      // ∂/∂α of C, S
  };
  PoleTerms terms(double alpha, double angle, const std::vector<double> &theta,
                  bool derivatives) const;
  // The same from a precomputed spectrum of the pole's shape (spectrum(α)): a caller that holds
  // α fixed (the pole design) computes it once instead of at every evaluation.
  PoleTerms terms(const GaussianPoleSpectrum &spectrum, double angle,
                  const std::vector<double> &theta, bool derivatives) const;
  GaussianPoleSpectrum spectrum(double alpha) const;
  void profile(const std::vector<Pole> &poles, const std::vector<double> &theta,
               std::vector<double> &Bn, std::vector<double> &Bt) const;

private:
  std::vector<double> exterior_; // μ0 n d_n (R_m/r)^(n+1), n = 0..N (e_0 = 0)
  int samples_;
};

PoleFitResult fit_poles(const Roller &nominal, const FluxScan &scan, double probe_radius,
                        const PoleFitOptions &options = {});

// The scan against the fitted model as the fit saw it: the scan rotated by the fitted encoder
// offset (its angles then are roller angles of the fitted case), the exact ring of the fitted
// poles at those angles. Its RMS error is the fit's residual.
FluxComparison compare_with_fitted_model(const FluxScan &scan, const PoleFitResult &fit,
                                         double probe_radius,
                                         const MultipoleRing::Options &ring_options = {});

// A residual RMS above this multiple of the noise means the model misses something real.
// (A right model leaves rms ≈ noise·√((m − p)/m); the noise estimate is good to a few %.)
constexpr double residual_far_above_noise = 1.5;

// "" when the fit's residual is compatible with the scan's noise, else a plain warning: how
// far above the noise it is and what to try.
std::string residual_warning(const PoleFitResult &fit);

// "shared", "per-pole", "fixed", "auto" (as the --fit-shape option spells them).
std::string shape_name(PoleFitOptions::Shape shape);

} // namespace magbrush
