#include "dem/wall_contact_slots.h"

#include "dem/particle_state.h"

namespace magbrush::dem {

namespace {
std::size_t U(std::int32_t v) { return static_cast<std::size_t>(v); }
} // namespace

void WallContactSlots::reset(std::size_t particles, std::size_t walls)
{
  has_walls_ = walls > 0;
  if (walls == 0)
    return;
  const std::size_t k = particles * per_particle;
  wall_.assign(k, -1);
  for (auto *a : doubles())
    a->assign(k, 0.0);
}

void WallContactSlots::extend(std::size_t particles)
{
  if (!has_walls_)
    return;
  const std::size_t k = particles * per_particle;
  wall_.resize(k, -1);
  for (auto *a : doubles())
    a->resize(k, 0.0);
}

void WallContactSlots::release_untouched(std::size_t i, const int *touching, int m)
{
  const std::size_t base = i * per_particle;
  for (int q = 0; q < per_particle; ++q)
  {
    const std::size_t sl = base + U(q);
    if (wall_[sl] < 0)
      continue;
    bool still = false;
    for (int c = 0; c < m; ++c)
      still = still || touching[c] == wall_[sl];
    if (!still)
    {
      wall_[sl] = -1;
      hx_[sl] = hy_[sl] = hz_[sl] = 0.0;
      fx_[sl] = fy_[sl] = fz_[sl] = tx_[sl] = ty_[sl] = tz_[sl] = 0.0;
    }
  }
}

std::size_t WallContactSlots::slot_for(std::size_t i, int wall)
{
  const std::size_t base = i * per_particle, none = base + per_particle;
  std::size_t sl = none;
  for (int q = 0; q < per_particle && sl == none; ++q)
    if (wall_[base + U(q)] == wall)
      sl = base + U(q);
  for (int q = 0; q < per_particle && sl == none; ++q)
    if (wall_[base + U(q)] < 0)
      sl = base + U(q);
  wall_[sl] = wall;
  return sl;
}

void WallContactSlots::permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch,
                               std::vector<std::int32_t> &iscratch)
{
  if (!has_walls_)
    return;
  std::vector<std::int32_t> &slot_order = slot_order_;
  slot_order.resize(order.size() * per_particle);
  for (std::size_t k = 0; k < order.size(); ++k)
    for (int s = 0; s < per_particle; ++s)
      slot_order[k * per_particle + U(s)] = order[k] * per_particle + s;
  permute_array(wall_, slot_order, iscratch);
  for (auto *a : doubles())
    permute_array(*a, slot_order, scratch);
}

std::vector<WallLoad> WallContactSlots::loads(std::size_t walls) const
{
  std::vector<WallLoad> loads(walls);
  for (std::size_t sl = 0; sl < wall_.size(); ++sl)
  {
    if (wall_[sl] < 0)
      continue;
    WallLoad &l = loads[U(wall_[sl])];
    l.force[0] += fx_[sl];
    l.force[1] += fy_[sl];
    l.force[2] += fz_[sl];
    l.torque[0] += tx_[sl];
    l.torque[1] += ty_[sl];
    l.torque[2] += tz_[sl];
    ++l.contacts;
  }
  return loads;
}

void WallContactSlots::contacts_of_wall(std::size_t w, std::vector<WallContactRecord> &out) const
{
  out.clear();
  const int wall = static_cast<int>(w);
  for (std::size_t sl = 0; sl < wall_.size(); ++sl)
  {
    if (wall_[sl] != wall)
      continue;
    WallContactRecord r;
    r.particle = static_cast<std::uint32_t>(sl / per_particle);
    r.force_on_wall = {fx_[sl], fy_[sl], fz_[sl]};
    r.torque_on_wall = {tx_[sl], ty_[sl], tz_[sl]};
    out.push_back(r);
  }
}

void WallContactSlots::write(CheckpointWriter &out) const
{
  out.put_array(wall_);
  for (const auto *a : doubles())
    out.put_array(*a);
}

void WallContactSlots::read(CheckpointReader &in)
{
  in.get_array(wall_);
  has_walls_ = !wall_.empty() || has_walls_;
  for (auto *a : doubles())
    in.get_array(*a);
}

std::size_t WallContactSlots::memory_bytes() const
{
  std::size_t b = wall_.capacity() * sizeof(std::int32_t);
  for (const auto *a : doubles())
    b += a->capacity() * sizeof(double);
  return b;
}

} // namespace magbrush::dem
