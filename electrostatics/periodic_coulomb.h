// Coulomb between point charges without a cutoff (Kweon eq. 6), over the periodic images of
// the scene (the slab periodic along z, or along x and z), optionally with the PAIR images of
// every charge in one grounded surface (the drum under its photoconductor: the image of
// charge j acting on charge i, layered_images.h).
//
// Near pairs exact, far field by expansion: the charges (and their images) are sorted into
// fine cells; pairs in cells within ±2 cells of each other (periodic images included) are
// summed exactly at the CURRENT positions on every call; everything else — the rest of the
// domain and every periodic image — is the cell-multipole far field of magnetics/
// (SourceKind::charges, cell_multipole_field.h), evaluated at rebuild() and HELD until the
// next rebuild (the caller decides when: the refresh interval is the accuracy knob; the held
// far field is what a checkpoint keeps).
//
// Periodic sums without a neutralising background: along one axis the field of a row of
// charges converges and Φ is defined up to a constant × the total charge; along two axes a
// net charge per cell acts as a charged sheet in free space (field σ/(2ε0) on either side).
// With pair images every charge brings its images' opposite total charge: the whole is
// neutral.
//
// A charge's own images (the self force) are NOT included here: that is the conductor-image
// term's (conductor_images.h), which sums the whole series exactly; the field of a charge's
// own images is excluded from the near sums and subtracted exactly from the far field.
//
// Every loop writes only its own target, in a fixed order: the same bits on any number of
// threads.
#pragma once

#include "electrostatics/grounded_surface.h"
#include "magnetics/cell_multipole_field.h"

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace magbrush::electrostatics {

struct CoulombSettings
{
  int order = 4;            // Taylor order of the cell multipoles (error vs cost: docs/electrostatics.md)
  double cell_size = 25e-6; // fine cell size [m]; the near field reaches ±2 cells
  bool single_precision = true; // M2L in single precision (magnetics/cell_multipole_field.h)
  int near_reach = 2;        // the near field: fine cells within ±near_reach (1 or 2)
};

class PeriodicCoulomb
{
public:
  PeriodicCoulomb(const CoulombSettings &settings, const std::array<double, 3> &box);

  // Pair images in `surface` (copied), `terms` explicit images per charge (layered_images.h);
  // a charge's images are computed at height max(h, floor) (floor: the particle radius, so a
  // particle overlapping the surface sees its images as if it touched it).
  void set_image_surface(const GroundedSurface &surface, int terms);
  bool has_images() const { return images_per_charge_ > 0; }

  // Sorts the charges (and images) into cells at these positions, lists the near pairs and
  // evaluates the far field, which is held. Positions are continuous (unwrapped) along
  // periodic axes; `floor` may be null (no floor).
  void rebuild(std::size_t n, const double *x, const double *y, const double *z, const double *q,
               const double *floor);

  // E [V/m] (3 per charge, overwritten) and, when `phi` is not null, the potential [V] (1 per
  // charge, overwritten; periodic: up to a constant × the net charge, see above): the held far
  // field plus the exact near pairs at the current positions (the same n, q, floor as at
  // rebuild(); each charge still in the cell it was sorted into, i.e. moved well under a cell).
  void field(const double *x, const double *y, const double *z, const double *q, const double *floor,
             double *E, double *phi);

  // Renewal of a few moved charges, for a field held between evaluations (the DEM term holds
  // it until something moved a hold distance: dem/force_terms/coulomb.h). The sources stand
  // where the last field() or renew() placed them; the charges `moved` (ascending) now stand
  // at x, y, z (the others' entries there are not read). Their images are placed again, and
  //  * for every other charge whose near row holds one of their sources, the change of those
  //    entries' field is ADDED to dE (3 per charge): `touched` lists those charges, ascending
  //    within each moved charge's rows (a charge may appear more than once);
  //  * the moved charges' own fields are computed afresh into E_moved (3 per moved charge):
  //    the held far field plus their near rows at the sources' present places.
  // So after it the held field of every charge is the field of the sources where they were
  // last placed, as if the whole had been evaluated then, each pair off by the moves of its
  // two charges since they were last placed. The far field is not touched (its own refresh).
  // Serial, in a fixed order: the same bits on any number of threads.
  void renew(const std::vector<std::uint32_t> &moved, const double *x, const double *y, const double *z,
             const double *q, const double *floor, std::vector<std::uint32_t> &touched, std::vector<double> &dE,
             std::vector<double> &E_moved);
  // Places the sources at these positions without evaluating anything (a restarted run puts
  // them back where the interrupted one had last placed them).
  void place(const double *x, const double *y, const double *z, const double *q, const double *floor)
  {
    place_sources(x, y, z, q, floor);
  }

  // The held far field (3 per charge, [V/m]) and far potential, for checkpoints.
  std::vector<double> &held_far_field() { return far_E_; }
  std::vector<double> &held_far_potential() { return far_phi_; }
  const std::vector<double> &held_far_field() const { return far_E_; }
  const std::vector<double> &held_far_potential() const { return far_phi_; }
  std::size_t charges() const { return n_; }
  // Wall time of the last rebuild's phases [s]: cells and near pair list, near rows, far field.
  struct Times
  {
    double cells = 0.0, rows = 0.0, far = 0.0;
  };
  const Times &last_rebuild_times() const { return times_; }
  std::size_t near_entries() const { return row_source_.size(); }
  const magnetics::CellMultipoleField &far_field() const { return *far_; }

private:
  CoulombSettings settings_;
  std::array<double, 3> box_;
  std::unique_ptr<magnetics::CellMultipoleField> far_;
  GroundedSurface surface_;
  int image_terms_ = 0, images_per_charge_ = 0;
  std::size_t n_ = 0; // real charges; sources = n_ × (1 + images_per_charge_)

  // Sources (charges, then the images of charge i at n + i·m + k) at the current positions.
  std::vector<double> sx_, sy_, sz_, sq_;
  std::vector<double> image_charge_, image_depth_; // scratch of one charge's series
  // Near rows of the real charges: sources and shifts (r = x_s + shift − x_i).
  std::vector<std::uint32_t> row_begin_, row_source_;
  std::vector<double> row_shift_;
  std::vector<std::uint32_t> row_fill_;
  std::vector<char> own_image_near_; // per image: is it its owner's near pair (not in the far field)
  // The near rows transposed, built at the first renew() after a rebuild: for each source,
  // the row entries that hold it, and each entry's target.
  bool columns_built_ = false;
  std::vector<std::uint32_t> column_begin_, column_entry_, entry_target_;
  std::vector<char> moving_; // per real charge: in the renewal under way
  // Held far field of the real charges (kernel sum × 1/(4πε0)), own images removed.
  std::vector<double> far_E_, far_phi_, scratch_phi_, scratch_E_;
  Times times_;

  void place_sources(const double *x, const double *y, const double *z, const double *q, const double *floor);
  void place_images_of(std::size_t i, const double *x, const double *y, const double *z, const double *q,
                       const double *floor);
  void build_columns();
  void build_rows(std::vector<char> &own_image_near);
  void remove_own_far_images(const std::vector<char> &own_image_near);
};

} // namespace magbrush::electrostatics
