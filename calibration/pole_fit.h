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
#pragma once

#include "calibration/flux_compare.h"
#include "calibration/flux_scan.h"
#include "coupling/case_model.h"
#include "coupling/multipole_ring.h"

#include <string>
#include <vector>

namespace magbrush {

struct PoleFitOptions
{
  enum class Shape { fixed, shared, per_pole } shape = Shape::shared;
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
  void profile(const std::vector<Pole> &poles, const std::vector<double> &theta,
               std::vector<double> &Bn, std::vector<double> &Bt) const;

private:
  std::vector<double> exterior_; // μ0 n d_n (R_m/r)^(n+1), n = 0..N (e_0 = 0)
  int samples_;
};

PoleFitResult fit_poles(const Roller &nominal, const FluxScan &scan, double probe_radius,
                        const PoleFitOptions &options = {});

} // namespace magbrush
