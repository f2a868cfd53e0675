// The contact law of Kawamoto et al., appendix A2–A7, as four small sub-models in the manner
// of LAMMPS GRANULAR (normal, damping, tangential, rolling), and the function that combines
// them for one contact. Particle–particle and particle–wall contacts use the same law; a wall
// is a partner of infinite mass and inertia (its 1/m and 1/I are zero).
//
// Sign conventions: n is the unit normal from particle i towards its partner; δ > 0 is the
// overlap; v_rel is the velocity of i's contact point relative to the partner's contact point;
// the returned force acts on i (the partner receives −F).
#pragma once

#include "dem/vector3.h"

#include <algorithm>
#include <cmath>

namespace magbrush::dem {

// Coefficients of one interaction type (species–species or species–wall material).
struct ContactCoefficients
{
  double effective_modulus = 0.0;  // E* = [(1−ν_i²)/E_i + (1−ν_j²)/E_j]⁻¹ [Pa]
  double effective_shear = 0.0;    // G* = [(2−ν_i)/G_i + (2−ν_j)/G_j]⁻¹ [Pa]
  double friction = 0.0;           // Coulomb sliding coefficient μ
  double rolling_friction = 0.0;   // μ_r in Kawamoto A7 (torque r μ_r |F_n|)
  double damping_normal = 0.0;     // α_n in c_n = α_n √(m* k_n) δ^¼
  double damping_tangential = 0.0; // α_t in c_t = α_t √(m* k_t)
};

// Hertz normal spring (A2–A3): F = k_n δ^{3/2}, k_n = (4/3) E* √R*.
struct HertzNormal
{
  static double stiffness(double E_star, double R_star) { return 4.0 / 3.0 * E_star * std::sqrt(R_star); }
  static double force(double k_n, double delta) { return k_n * delta * std::sqrt(delta); }
  static double energy(double k_n, double delta) { return 0.4 * k_n * delta * delta * std::sqrt(delta); }
};

// Voigt dashpot of Kawamoto (A3): c_n = α √(m* k_n) δ^{1/4}. The LIGGGHTS/LAMMPS restitution
// form (γ_n = 2√(5/6) β √(S_n m*), S_n = 2E*√(R*δ), β = ln e/√(ln²e + π²)) is the same
// function of δ with α = √5 |β| (contact_parameters.h), so one dashpot serves both.
struct ViscoelasticDamping
{
  static double normal(double alpha, double m_star, double k_n, double delta)
  {
    return alpha * std::sqrt(m_star * k_n * std::sqrt(delta));
  }
  static double tangential(double alpha, double m_star, double k_t)
  {
    return alpha * std::sqrt(m_star * k_t);
  }
};

// Mindlin tangential spring with dashpot and Coulomb limit (A4–A6):
//   F_t = −k_t ξ − c_t v_t,  k_t = 8 G* √(R* δ),  |F_t| ≤ μ F_n.
// ξ is the accumulated tangential displacement (the contact history). Each step it is first
// turned into the current tangent plane (the pair frame rotates as the particles roll round
// each other), then incremented by v_t dt. We remove the normal component WITHOUT restoring
// the old magnitude: that equals the exact rotation to first order in the step's rotation
// angle, and — unlike LAMMPS's magnitude-preserving rescale — can never pump the spring up,
// which is reported to make small particles stick to large ones (lammps/lammps PR #4244).
// When sliding, ξ is reset to the spring extension that carries the Coulomb force
// (ξ = −(F_t + c_t v_t)/k_t, as in LAMMPS and Luding 2008), so stick resumes without a jump.
struct MindlinTangential
{
  // k_t = 8 G* a with the contact radius a = √(R* δ), written as √R* √δ: the kernel shares
  // both roots with the normal spring (and this is the form its bits are pinned to).
  static double stiffness(double G_star, double R_star, double delta)
  {
    return 8.0 * G_star * std::sqrt(R_star) * std::sqrt(delta);
  }
  static void rotate_into_tangent_plane(Vector3 &xi, const Vector3 &n)
  {
    xi = xi - dot(xi, n) * n;
  }
  // Returns the tangential force on i and updates ξ. Written without branches (the sliding
  // case is a select), so that the pair kernel vectorises; the result is the same as the
  // branchy form, bit for bit.
  static Vector3 force(Vector3 &xi, const Vector3 &v_t, double k_t, double c_t, double mu,
                       double f_n, double dt)
  {
    xi += dt * v_t;
    const Vector3 f_stick = -(k_t * xi) - c_t * v_t;
    const double limit = mu * f_n;
    const double f2 = dot(f_stick, f_stick);
    const bool sliding = f2 > limit * limit; // implies f2 > 0
    const double scale = sliding ? limit / std::sqrt(sliding ? f2 : 1.0) : 1.0;
    const Vector3 f = scale * f_stick;
    // Sliding: the spring extension that carries the Coulomb force (k_t > 0 while touching).
    const double inv_k = k_t > 0.0 ? -1.0 / (k_t > 0.0 ? k_t : 1.0) : 0.0;
    const Vector3 xi_slide = inv_k * (f + c_t * v_t);
    xi = {sliding ? xi_slide.x : xi.x, sliding ? xi_slide.y : xi.y, sliding ? xi_slide.z : xi.z};
    return f;
  }
};

// Rolling friction (A7, second term): a torque of magnitude r μ_r |F_n| opposing rolling.
// Kawamoto uses each particle's own ω direction; we use the RELATIVE rolling velocity
// (ω_i − ω_j with the twist along n removed), which is the same for one particle on a fixed
// wall and is frame-independent (a bead riding rigidly on a turning sleeve feels none).
// A constant-magnitude torque chatters when ω_roll ≈ 0; it is therefore capped so that one
// step cannot reverse the relative rolling velocity (then it acts like a stiff viscous lock).
// Branch-free like the tangential spring: μ_r = 0, F_n = 0 or ω_roll = 0 give zero torques.
struct RollingFriction
{
  struct Torques
  {
    Vector3 on_i, on_j;
  };
  static Torques torque(const Vector3 &w_rel, const Vector3 &n, double mu_r, double f_n,
                        double r_i, double r_j, double inv_I_i, double inv_I_j, double dt)
  {
    const Vector3 w_roll = w_rel - dot(w_rel, n) * n;
    const double w = norm(w_roll);
    const double m = std::max(0.0, mu_r * f_n); // torque magnitude before the cap
    // Change of |ω_roll| in one step under the full torques: m dt (r_i/I_i + r_j/I_j).
    const double full_change = m * dt * (r_i * inv_I_i + r_j * inv_I_j);
    const bool capped = full_change > w; // implies full_change > 0
    const double scale = capped ? w / (capped ? full_change : 1.0) : 1.0;
    const double inv_w = w > 0.0 ? 1.0 / (w > 0.0 ? w : 1.0) : 0.0;
    const Vector3 dir = inv_w * w_roll;
    Torques t;
    t.on_i = -(scale * m * r_i) * dir;
    t.on_j = (scale * m * r_j) * dir;
    return t;
  }
};

// Van der Waals adhesion: the Derjaguin limit of Hamaker's sphere–sphere interaction,
//   F = A R / (6 z²),  R = ρ_i ρ_j / (ρ_i + ρ_j),
// attractive, along the line of centres, with z the gap between the surfaces. The plane is
// the limit ρ_j → ∞ (F = A ρ_i / (6 z²)). It is exact to first order in z/ρ: the relative
// error of the Derjaguin form against the exact Hamaker force is ≈ z/ρ (tests/dem/
// test_adhesion.cpp measures it). The gap is floored at the cut-off distance z0 (≈ 0.4 nm,
// the interatomic distance at contact): for z ≤ z0, and throughout a Hertz overlap, the force
// is the pull-off force F0 = A R / (6 z0²). Beyond the range z_c = z0 / √f, where it has
// fallen to the fraction f of F0, it is cut to zero (the neighbour list and the wall
// detection reach that far: ContactTable::adhesion_range()).
//
// ρ is the radius of the bodies where they touch: real toner touches through asperities and
// silica additives (10–100 nm); a smooth 7 µm toner would stick with ≈ 0.3 µN, tens of
// times any electric force on it. Each material may give it (materials.*.adhesion_radius); ρ = min(particle radius,
// asperity radius), ∞ for a wall without one (a flat wall).
//
// In the contact law the attraction is added to the normal force (DMT): it loads the Hertz
// spring, so at rest the elastic force is the external load PLUS F0, and the Coulomb limit
// μ F_n and the rolling torque μ_r F_n, which use that elastic force, see the adhesion. The
// body detaches when the other forces exceed F0.
struct AdhesionCoefficients
{
  double hamaker = 0.0;     // A₁₂ [J]; 0: no adhesion
  double asperity_i = 0.0;  // asperity radius of i's material [m]; +∞: the particle's radius
  double asperity_j = 0.0;  // the partner's (a wall: +∞ = flat)
};

struct HamakerAdhesion
{
  // The radius that sets the force: ρ = min(r, asperity) for each body, combined in series.
  static double radius(double r_i, double asperity_i, double r_j, double asperity_j)
  {
    const double a = std::min(r_i, asperity_i), b = std::min(r_j, asperity_j);
    return a * b / (a + b);
  }
  // A particle against a wall (asperity_w = +∞: a flat wall, R = ρ_i).
  static double wall_radius(double r_i, double asperity_i, double asperity_w)
  {
    const double a = std::min(r_i, asperity_i);
    return std::isinf(asperity_w) ? a : a * asperity_w / (a + asperity_w);
  }
  // Magnitude of the attraction at gap z (z < 0: overlapping), z floored at z0.
  static double force(double A, double R, double z, double z0)
  {
    const double s = std::max(z, z0);
    return A * R / (6.0 * s * s);
  }
  // The gap beyond which the force is cut: there it has fallen to `fraction` of F0.
  static double range(double z0, double fraction) { return z0 / std::sqrt(fraction); }
};

// What one contact needs to know about its two bodies.
struct ContactKinematics
{
  Vector3 n;                 // unit normal from i towards the partner
  double overlap = 0.0;      // δ > 0
  double lever_i = 0.0;      // distance from i's centre to the contact plane
  double lever_j = 0.0;      // same for the partner (0 for walls)
  Vector3 v_rel;             // contact-point velocity of i relative to the partner
  Vector3 w_rel;             // ω_i − ω_partner
  double R_star = 0.0;       // r_i r_j / (r_i + r_j) (walls: r_i)
  double m_star = 0.0;       // m_i m_j / (m_i + m_j) (walls: m_i)
  double radius_i = 0.0, radius_j = 0.0;
  double inv_inertia_i = 0.0, inv_inertia_j = 0.0; // partner: 0 for walls
};

struct ContactOutcome
{
  Vector3 force_i;   // total contact force on i (partner receives the opposite)
  Vector3 torque_i;  // torque on i
  Vector3 torque_j;  // torque on the partner (about its own centre)
  double normal_force = 0.0;
};

// The whole law for one touching contact: normal + damping + tangential + rolling.
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline ContactOutcome evaluate_contact(const ContactCoefficients &c, const ContactKinematics &k,
                                       Vector3 &history, double dt)
{
  ContactOutcome out;
  // The sub-models above, each formula in one place. They share √R* and √δ: the compiler
  // computes each root once (sqrt has no side effects with -fno-math-errno, dem/CMakeLists.txt).
  const double k_n = HertzNormal::stiffness(c.effective_modulus, k.R_star);
  // v_rel·n > 0: i moves towards the partner (approach); the dashpot opposes it.
  const double approach = dot(k.v_rel, k.n);
  const double c_n = ViscoelasticDamping::normal(c.damping_normal, k.m_star, k_n, k.overlap);
  // Magnitude of the repulsive normal force; a dashpot may not pull the bodies together.
  const double f_n = std::max(0.0, HertzNormal::force(k_n, k.overlap) + c_n * approach);
  out.normal_force = f_n;

  const Vector3 v_t = k.v_rel - approach * k.n;
  const double k_t = MindlinTangential::stiffness(c.effective_shear, k.R_star, k.overlap);
  const double c_t = ViscoelasticDamping::tangential(c.damping_tangential, k.m_star, k_t);
  MindlinTangential::rotate_into_tangent_plane(history, k.n);
  const Vector3 f_t = MindlinTangential::force(history, v_t, k_t, c_t, c.friction, f_n, dt);

  out.force_i = (-f_n) * k.n + f_t;
  // Lever arms to the contact plane: torque on i is (a_i n) × F_t; the partner gets −F_t at
  // −a_j n, i.e. (a_j n) × F_t.
  const Vector3 n_x_ft = cross(k.n, f_t);
  const auto roll = RollingFriction::torque(k.w_rel, k.n, c.rolling_friction, f_n, k.radius_i,
                                            k.radius_j, k.inv_inertia_i, k.inv_inertia_j, dt);
  out.torque_i = k.lever_i * n_x_ft + roll.on_i;
  out.torque_j = k.lever_j * n_x_ft + roll.on_j;
  return out;
}

} // namespace magbrush::dem
