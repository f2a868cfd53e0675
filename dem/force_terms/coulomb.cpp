#include "dem/force_terms/coulomb.h"

#include "dem/checkpoint_file.h"
#include "dem/periodic_unwrap.h"
#include "dem/dem_system.h"
#include "dem/force_terms/force_term_registry.h"
#include "dem/force_terms/held_forces.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace magbrush::electrostatics {

CoulombTermSettings CoulombTermSettings::from_case(const Case &c)
{
  CoulombTermSettings s;
  s.far.order = c.electric.coulomb_order;
  s.far.cell_size = c.electric.coulomb_cell;
  s.refresh = c.electric.coulomb_refresh;
  s.image_terms = c.electric.pair_image_terms;
  // Pair images in the drum (where the developed layer sits) when the scene has a drum and
  // the conductors' images are on; the sleeve's images act on each charge itself only
  // (conductor_images.h).
  if (c.drum.present && c.sleeve && c.electric.conductor_images && c.electric.pair_image_terms > 0)
  {
    GroundedSurface drum;
    drum.shape = GroundedSurface::Shape::cylinder;
    const Vec2 centre = c.drum.center(c.sleeve->radius);
    drum.centre_x = centre[0];
    drum.centre_y = centre[1];
    drum.radius = c.drum.radius;
    drum.layer = LayeredImages(c.drum.pc_eps_r, c.drum.pc_thickness);
    s.image_surface = drum;
  }
  return s;
}

CoulombTerm::CoulombTerm(const CoulombTermSettings &settings, const std::array<double, 3> &box)
  : settings_(settings), box_(box), coulomb_(settings.far, box)
{
  if (settings.image_surface)
    coulomb_.set_image_surface(*settings.image_surface, settings.image_terms);
}

void CoulombTerm::select(const dem::ParticleState &state)
{
  index_.clear();
  q_.clear();
  radius_.clear();
  for (std::size_t k = 0; k < state.size(); ++k)
    if (state.charge[k] != 0.0)
    {
      index_.push_back(static_cast<std::uint32_t>(k));
      q_.push_back(state.charge[k]);
      radius_.push_back(state.radius[k]);
    }
  const std::size_t n = index_.size();
  for (auto *v : {&x_, &y_, &z_})
    v->resize(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    x_[k] = state.x[index_[k]];
    y_[k] = state.y[index_[k]];
    z_[k] = state.z[index_[k]];
  }
  E_.assign(3 * n, 0.0);
  state_size_ = state.size();
  index_compactly();
  must_select_ = false;
  must_rebuild_ = true;
}

void CoulombTerm::index_compactly()
{
  compact_of_.assign(state_size_, -1);
  for (std::size_t k = 0; k < index_.size(); ++k)
    compact_of_[index_[k]] = static_cast<std::int32_t>(k);
}

void CoulombTerm::gather(const dem::ParticleState &state)
{
  // Unwrapped along periodic axes (dem/periodic_unwrap.h). A changed charge invalidates the
  // held far field.
  const std::size_t n = index_.size();
  std::vector<double> *const mine[3] = {&x_, &y_, &z_};
  dem::follow_unwrapped(state, index_, box_, mine);
  for (std::size_t k = 0; k < n; ++k)
    if (state.charge[index_[k]] != q_[k])
    {
      q_[k] = state.charge[index_[k]];
      must_rebuild_ = true;
    }
}

bool CoulombTerm::moved_too_far() const
{
  const double limit = settings_.max_move_cells * settings_.far.cell_size, limit2 = limit * limit;
  for (std::size_t k = 0; k < index_.size(); ++k)
  {
    const double dx = x_[k] - bx_[k], dy = y_[k] - by_[k], dz = z_[k] - bz_[k];
    if (dx * dx + dy * dy + dz * dz > limit2)
      return true;
  }
  return false;
}

void CoulombTerm::rebuild(double t)
{
  bx_ = x_;
  by_ = y_;
  bz_ = z_;
  coulomb_.rebuild(index_.size(), bx_.data(), by_.data(), bz_.data(), q_.data(), radius_.data());
  built_at_ = t;
  must_rebuild_ = false;
  ++evaluations_;
}

void CoulombTerm::add_forces(const dem::ParticleState &state, dem::ForceBuffers &forces, double t)
{
  const bool exchange = must_select_ || state.size() != state_size_;
  if (exchange)
    select(state);
  const std::size_t n = index_.size();
  if (n == 0)
    return;
  const bool was_stale = must_rebuild_;
  gather(state);
  const bool charge_changed = !was_stale && must_rebuild_;
  if (must_rebuild_ || t - built_at_ >= settings_.refresh || moved_too_far())
  {
    long &cause = exchange || was_stale      ? causes_.exchange
                  : charge_changed           ? causes_.charge
                  : t - built_at_ >= settings_.refresh ? causes_.refresh
                                                       : causes_.move;
    ++cause;
    rebuild(t);
  }
  coulomb_.field(x_.data(), y_.data(), z_.data(), q_.data(), radius_.data(), E_.data(), nullptr);
  for (std::size_t k = 0; k < n; ++k)
  {
    const std::size_t i = index_[k];
    forces.fx[i] += q_[k] * E_[3 * k];
    forces.fy[i] += q_[k] * E_[3 * k + 1];
    forces.fz[i] += q_[k] * E_[3 * k + 2];
  }
}

void CoulombTerm::particles_reordered(const std::vector<std::int32_t> &order)
{
  if (index_.empty())
    return;
  if (order.size() != state_size_)
  {
    must_select_ = true;
    return;
  }
  std::vector<std::uint32_t> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    new_index[static_cast<std::size_t>(order[k])] = static_cast<std::uint32_t>(k);
  for (auto &i : index_)
    i = new_index[i];
  index_compactly();
}

void CoulombTerm::particles_changed(const std::vector<std::int32_t> & /*origin*/)
{
  // Particles entered or left: the compact order no longer names the charged particles — also
  // when as many entered as left, so that the count alone would not tell — so they are
  // selected again and the cells rebuilt.
  must_select_ = true;
}

void CoulombTerm::write_state(dem::CheckpointWriter &out) const
{
  out.put<std::uint64_t>(state_size_);
  // 0: the held far field is current; 1: rebuild it at the next step; 2: select the charged
  // particles again first (an exchange happened since the last step).
  out.put<std::uint8_t>(must_select_ ? 2 : must_rebuild_ ? 1 : 0);
  out.put_array(index_);
  for (const auto *v : {&q_, &radius_, &x_, &y_, &z_, &bx_, &by_, &bz_})
    out.put_array(*v);
  out.put<double>(built_at_);
  out.put<std::int64_t>(evaluations_);
  out.put_array(coulomb_.held_far_field());
  out.put_array(coulomb_.held_far_potential());
}

void CoulombTerm::read_state(dem::CheckpointReader &in)
{
  state_size_ = static_cast<std::size_t>(in.get<std::uint64_t>());
  const std::uint8_t pending = in.get<std::uint8_t>();
  const bool stale = pending != 0;
  in.get_array(index_);
  for (auto *v : {&q_, &radius_, &x_, &y_, &z_, &bx_, &by_, &bz_})
    in.get_array(*v);
  built_at_ = in.get<double>();
  evaluations_ = static_cast<long>(in.get<std::int64_t>());
  std::vector<double> far_E, far_phi;
  in.get_array(far_E);
  in.get_array(far_phi);
  E_.assign(3 * index_.size(), 0.0);
  must_select_ = pending == 2;
  must_rebuild_ = stale;
  if (!stale && !index_.empty())
  {
    // The cells and near rows of the last rebuild (deterministic from the stored positions),
    // then the held far field as it was.
    coulomb_.rebuild(index_.size(), bx_.data(), by_.data(), bz_.data(), q_.data(), radius_.data());
    if (far_E.size() != coulomb_.held_far_field().size() || far_phi.size() != coulomb_.held_far_potential().size())
      throw std::runtime_error("checkpoint: the Coulomb term's held far field has " + std::to_string(far_E.size() / 3) +
                               " charges, its particles " + std::to_string(index_.size()) + ".");
    coulomb_.held_far_field() = far_E;
    coulomb_.held_far_potential() = far_phi;
    // The sources where the interrupted run last placed them: each charge where it was last
    // evaluated or renewed.
    coulomb_.place(x_.data(), y_.data(), z_.data(), q_.data(), radius_.data());
  }
  index_compactly();
}

bool CoulombTerm::renew_moved(const dem::ParticleState &state, dem::ForceBuffers &held, double t,
                              const std::vector<std::uint32_t> &moved)
{
  // Only between rebuilds of an unchanged set of charges: otherwise everybody is evaluated.
  if (must_select_ || must_rebuild_ || state.size() != state_size_ || index_.empty() ||
      t - built_at_ >= settings_.refresh)
    return false;
  moved_.clear();
  for (const std::uint32_t i : moved)
    if (const std::int32_t k = compact_of_[i]; k >= 0)
      moved_.push_back(static_cast<std::uint32_t>(k));
  if (moved_.empty())
    return true; // only uncharged particles moved: no Coulomb force changes
  std::sort(moved_.begin(), moved_.end()); // compact order: the same on any number of threads
  const double limit = settings_.max_move_cells * settings_.far.cell_size;
  for (const std::uint32_t k : moved_)
  {
    const std::size_t i = index_[k];
    x_[k] = dem::nearest_image(state.x[i], x_[k], box_[0]);
    y_[k] = dem::nearest_image(state.y[i], y_[k], box_[1]);
    z_[k] = dem::nearest_image(state.z[i], z_[k], box_[2]);
    const double dx = x_[k] - bx_[k], dy = y_[k] - by_[k], dz = z_[k] - bz_[k];
    if (dx * dx + dy * dy + dz * dz > limit * limit)
      return false; // left its cell's reach: the cells must be rebuilt
  }
  coulomb_.renew(moved_, x_.data(), y_.data(), z_.data(), q_.data(), radius_.data(), touched_, dE_, E_moved_);
  // The others' held forces change by their charge times the field's change (each applied
  // once: a charge listed again finds its change already taken), the moved ones' are new.
  for (const std::uint32_t k : touched_)
  {
    const std::size_t i = index_[k];
    held.fx[i] += q_[k] * dE_[3 * k];
    held.fy[i] += q_[k] * dE_[3 * k + 1];
    held.fz[i] += q_[k] * dE_[3 * k + 2];
    dE_[3 * k] = dE_[3 * k + 1] = dE_[3 * k + 2] = 0.0;
  }
  for (std::size_t a = 0; a < moved_.size(); ++a)
  {
    const std::uint32_t k = moved_[a];
    const std::size_t i = index_[k];
    held.fx[i] = q_[k] * E_moved_[3 * a];
    held.fy[i] = q_[k] * E_moved_[3 * a + 1];
    held.fz[i] = q_[k] * E_moved_[3 * a + 2];
  }
  return true;
}

std::string CoulombTerm::cost_note() const
{
  // (How often the moved were renewed alone, the hold around the term counts.)
  return "far field rebuilt " + std::to_string(evaluations_) + " times; since this run (re)started " +
         std::to_string(causes_.exchange) + " after exchanges, " + std::to_string(causes_.charge) +
         " for changed charges, " + std::to_string(causes_.refresh) + " at the refresh interval, " +
         std::to_string(causes_.move) + " for a charge beyond a quarter cell";
}

namespace {
// Held, the charges that moved the hold distance are renewed alone while they are at most this
// share of the particles (the fast few: free toner across the gap), everybody when more moved
// (the developer riding the sleeve crosses the distance together). A renewal costs its
// charges' entries (~10 rows' worth each) against every row: far below the whole up to this
// share. Measured on the Kweon development nip: docs/electrostatics.md.
constexpr double renew_share = 0.05;

// On when some population is charged, unless switched off.
std::string coulomb_not_needed_because(const Case &c)
{
  if (!c.electric.coulomb)
    return "electric.coulomb is false";
  if (c.has_charged_population())
    return "";
  return "no population is charged";
}

const bool registered = dem::register_force_term(
    {"Coulomb", dem::force_term_order::coulomb, coulomb_not_needed_because,
     [](const Case &c, const dem::DemSystem &system) -> std::unique_ptr<dem::ForceTerm> {
       std::optional<dem::RotatingFrame> frame;
       if (c.electric.coulomb_hold_frame == Electric::HoldFrame::sleeve && c.sleeve)
       {
         // The sleeve turns about the z axis through the origin (geometry/wall_primitives.cpp).
         frame = dem::RotatingFrame{};
         frame->angle = [sleeve = *c.sleeve](double t) { return sleeve.turned(t); };
       }
       return dem::held_for(std::make_unique<CoulombTerm>(CoulombTermSettings::from_case(c), system.box().length),
                            c.electric.hold_distance, system.box().length, {}, renew_share, std::move(frame));
     }});
} // namespace

} // namespace magbrush::electrostatics
