// Settings of the DEM magnetics: the interaction model and its accuracy knobs.
#pragma once

#include <string>

namespace magbrush {
struct DemSettings;
}

namespace magbrush::magnetics {

// Which interaction model the carriers obey.
//  * point_dipole:  each bead is a dipole induced by the APPLIED field alone,
//                   p_j = α_j B_applied(x_j); the beads then attract/repel as point dipoles.
//                   No mutual induction. (Cheapest; underestimates chains.)
//  * mutual_dipole: the model of the papers (Kawamoto A8–A11, Kweon eq. 2–5): p_j = α_j B_j
//                   with B_j the applied field PLUS the dipole fields of all other beads within
//                   the cutoff, solved self-consistently.
//  * corrected:     mutual_dipole plus, for close pairs, the difference between the exact
//                   two-sphere force (multipole series) and the isolated-pair mutual-dipole
//                   force, both evaluated in the local field the pair sits in.
enum class DipoleModel { point_dipole, mutual_dipole, corrected };

DipoleModel parse_dipole_model(const std::string &name); // throws std::invalid_argument
std::string to_string(DipoleModel model);

// What the torque outputs receive. A homogeneous isotropic sphere feels no magnetic torque:
// its induced magnetisation is not fixed to the body, so rotating it changes nothing. With
// converged mutual induction the papers' p × B (A8) is zero up to the solver tolerance; in
// the point_dipole model it is an artefact (p follows the applied field only).
enum class TorqueModel
{
  none,  // add nothing (physically exact for isotropic beads): the default
  paper  // add p_j × B_j (Kawamoto A8), B_j the local field at the bead
};

// How the dipole sums treat what lies beyond the near field.
//  * none:           a hard cutoff (cutoff_diameters; Kawamoto: everything beyond is dropped),
//                    optionally with the slab tail correction;
//  * cell_multipole: no cutoff: exact pairs between beads in neighbouring fine cells, and the
//                    whole rest of the domain (every periodic image) through the cell
//                    multipole method (cell_multipole_field.h), O(N).
enum class FarField { none, cell_multipole };

FarField parse_far_field(const std::string &name); // throws std::invalid_argument
std::string to_string(FarField far_field);

// When held magnetic forces are stale before the refresh interval elapses, and what that
// triggers (InducedDipoles::check_staleness / refresh_locally).
//  * absolute: a bead moved more than staleness_fraction × its radius since the last
//              evaluation → a full refresh (every bead, the far field, all pairs). In a
//              flowing nip a single fast bead fires it every ~20–30 steps.
//  * local:    the same trigger, but a LOCAL refresh around the beads that moved: their
//              applied field and near pair tensors, the dipoles of them and their neighbours
//              within local_region_radius (Jacobi sweeps with everything else held), and the
//              forces of every pair touching a dipole that changed (Newton's third law exact
//              per pair). The far field and the other dipoles are held until the refresh
//              interval elapses; a full refresh when the region would exceed
//              local_region_limit of the beads or a neighbour list expired.
//  * relative: the dipole–dipole forces depend on the beads' RELATIVE positions: a pair
//              closer than relative_check_radius (mean radii) is stale when its pair vector
//              changed by more than staleness_fraction × the mean radius since its tensor was
//              evaluated; a bead is stale for the applied field (which varies on the mm scale)
//              when it moved more than absolute_factor × staleness_fraction × its radius.
//              Stale pairs and beads get the local refresh. A brush carried rigidly by the
//              sleeve triggers nothing.
enum class StalenessMode { absolute, local, relative };

StalenessMode parse_staleness_mode(const std::string &name); // throws std::invalid_argument
std::string to_string(StalenessMode mode);

// The member initialisers are the defaults of a case file (the dem.magnetic_* keys in
// case/case_keys_magnetics.cpp, dem.verlet_skin in case/case_keys_dem.cpp): settings
// built in code run what a user's default case runs, and a test or bench that wants another
// scene sets it explicitly. tests/case/test_module_defaults.cpp fails when the two disagree.
// The fields without a case key (torque, max_sweeps, the local-refresh and far-field details)
// have their defaults only here.
struct MagneticSettings
{
  DipoleModel model = DipoleModel::corrected;
  TorqueModel torque = TorqueModel::none;

  // Interaction cutoff: a pair interacts when its centre distance is below the cutoff.
  // cutoff_length > 0 gives it in metres; otherwise cutoff_diameters × the mean diameter
  // of the beads. Used only with far_field = none (the papers used 4 to 8 diameters; 12
  // gives ~1 % force error in a brush with the slab tail, docs/magnetics.md).
  double cutoff_diameters = 12.0;
  double cutoff_length = 0.0;

  // Verlet skin of the magnetic neighbour list, as a fraction of the mean diameter: the list
  // holds pairs within cutoff + skin and is rebuilt when a bead moved more than skin/2.
  double skin_fraction = 0.3;

  // Mutual induction: Jacobi sweeps until max_j |Δp_j| ≤ tolerance × max_j |p_j|.
  double tolerance = 1e-4; // force error ~1e-5 (docs/magnetics.md)
  int max_sweeps = 200;

  // Refresh bookkeeping for a DEM that holds the magnetic forces between evaluations:
  // refresh after refresh_interval [s] (0 = every step), or earlier as soon as some bead
  // moved more than staleness_fraction × its radius since the last evaluation.
  double refresh_interval = 0.0;
  double staleness_fraction = 0.05;
  StalenessMode staleness_mode = StalenessMode::relative;
  // local: largest region (moved beads and their near neighbours) refreshed locally, as a
  // fraction of all beads (a region of up to 64 beads always is); beyond it a full refresh.
  double local_region_limit = 0.5;
  // local: the region whose dipoles are solved again: the moved beads and their near
  // neighbours closer than this many of the moved bead's radii (a bead 3 diameters away
  // changes its dipole by < 0.5 % of the moved bead's relative change: 2β(a/r)³).
  double local_region_radius = 6.0;
  // local: once some bead is past the staleness limit, every bead past this fraction of it
  // joins the refresh (batching: the next trigger comes later).
  double local_batch_fraction = 0.5;
  // local: besides the moved beads, the pairs (and totals) of the region's beads whose dipole
  // changed by more than this fraction are recomputed; smaller changes are held (0 = every
  // bead of the region: then the local refresh equals a full one up to the held far field
  // and the dipoles outside the region).
  double local_dipole_change = 1e-3;
  // relative: the pairs watched (closer than this many mean radii at the last full
  // evaluation, plus the skin), and the absolute bound for the applied field as a multiple
  // of staleness_fraction (the roller's field changes by ~0.3 % over 5 × 0.05 radii).
  double relative_check_radius = 4.0;
  double absolute_factor = 5.0;

  // Particles entering or leaving (the inflow / outflow exchange, DemSystem::
  // exchange_particles): true = an exchange forces no evaluation of its own: an empty one
  // changes nothing, the leavers stay as frozen sources and the newcomers wait (no magnetic
  // force) until the next full evaluation (the interval, a list expiry, a large region),
  // which admits them — at most magnetic_refresh later. false = a full evaluation with new
  // lists at every exchange, even an empty one (the behaviour before; docs/magnetics.md
  // "Particle exchange").
  bool defer_exchange = true;
  // With defer_exchange and the cell-multipole far field: admit the exchange at the next
  // step without a rebuild (InducedDipoles::admit): the newcomers join the kept fine cells
  // and pair lists, the leavers stay as inert holes (no dipole, no force) until the lists
  // are rebuilt anyway, and the newcomers' dipoles and their neighbourhood's (and the
  // leavers' neighbours') are solved by a local refresh. Where that cannot be done (a
  // newcomer in an empty fine cell, expired lists, no far field) the exchange waits as
  // above. docs/magnetics.md "Particle exchange" (regulation cell at 16 ms: as accurate as
  // evaluating every exchange, at the deferral's cost).
  bool admit_exchange = true;
  // Between evaluations, hold the dipoles instead of the forces: every step the close pairs'
  // forces (the relative trigger's watched pairs: within relative_check_radius mean radii +
  // skin) are evaluated at the current pair vectors from the held dipoles and local fields
  // (live_pairs.h); the rest of each held force stays. 5–8× less held-force error at the
  // same schedule on the flowing nip, so that the staleness limit and the refresh interval
  // can be larger (docs/magnetics.md "Holding the dipoles instead of the forces").
  bool hold_dipoles = false;
  // hold_dipoles: the live pairs are those within live_pair_radius mean radii at their last
  // tensor evaluation (2 = touching), and their changes are evaluated every live_pair_steps
  // steps.
  double live_pair_radius = 3.0;
  int live_pair_steps = 20;

  // `corrected`: the exact-minus-dipole pair correction is applied fully for centre
  // distances below switch_begin (in mean pair radii, 2 = touching) and blended smoothly to
  // zero at switch_end (C¹ smoothstep). Tables extend to switch_end.
  double switch_begin = 4.0;
  double switch_end = 5.0;

  // Laterally periodic slabs (exactly two periodic axes, the third open: Kawamoto's
  // compression box, a brush on a plane). The dipole sums of a polarised slab converge only
  // like 1/R_c (the cut-off rim of a polarised layer), so a hard cutoff leaves errors of
  // several per cent even at 8–16 diameters. This adds the mean field of everything beyond
  // the cutoff: every bead's periodic images smeared into a uniform sheet, minus the disc of
  // that sheet inside the cutoff sphere (the infinite sheet itself has no field off-sheet):
  //   B_tail,i = −μ0/(4 R_c A) Σ_k (1 − h_ik²/R_c²)₊ (2 p_k,n n̂ − p_k,t),   h_ik = u_k − u_i,
  // with A the periodic cell area, u the coordinate along the open axis n̂. Linear in p, so it
  // joins the mutual induction; its force is n̂ p_i·∂B_tail/∂u_i (pairwise even kernel, so
  // Newton's third law holds up to round-off). Cost O(N log N) per sweep (prefix sums).
  bool slab_tail_correction = false;

  // Far field (cell_multipole): fine cell size in mean diameters, Taylor order p, near reach
  // in fine cells (2: the 125 cells around a bead's cell are exact pairs), and far-field
  // evaluations per compute: the far field is held fixed through the Jacobi sweeps (the
  // near field is updated every sweep) and evaluated far_passes times in all, each time
  // from the latest dipoles (1 = once, from the previous call's dipoles: the far field lags
  // one refresh); a cold start (no previous dipoles) does one pass more.
  FarField far_field = FarField::cell_multipole;
  double far_cell_diameters = 1.5;
  int far_order = 2;
  int far_near_reach = 2;
  int far_passes = 1;
  bool far_single_precision = true; // M2L translations in float (error table: harmless)

  // The settings a case asks for (model, far field, cutoff, tolerance, refresh, skin).
  static MagneticSettings from_case(const DemSettings &dem);
};

} // namespace magbrush::magnetics
