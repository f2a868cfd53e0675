// The memory of particle–wall contacts: every particle owns a few slots (at most
// `per_particle` walls touch it at once), each holding the wall it touches (−1: free), the
// tangential spring's history ξ of that contact (Mindlin, contact_law.h) and what the wall
// feels from it (force and torque, for the wall loads and the measurements).
//
// Ten parallel arrays (structure of arrays), slot s of particle i at i * per_particle + s;
// they move with the particles when the engine re-sorts them, and go into checkpoints.
#pragma once

#include "dem/checkpoint_file.h"
#include "dem/vector3.h"

#include <array>
#include <cstdint>
#include <vector>

namespace magbrush::dem {

// Total load of the particles on one wall [N, N m] (torque about the wall's axis for
// cylinders, about the z axis through the origin otherwise).
struct WallLoad
{
  std::array<double, 3> force{0, 0, 0};
  std::array<double, 3> torque{0, 0, 0};
  long contacts = 0;
};

// One particle touching one wall at the current step: what the wall feels from it. Used by
// measurements (pressure on the drum, beads touching the compression plate, slip speed).
struct WallContactRecord
{
  std::uint32_t particle = 0;  // current index into particles() (not stable: see `id`)
  Vector3 force_on_wall;       // −(contact force on the particle) [N]
  Vector3 torque_on_wall;      // about the wall's reference point [N m]
};

class WallContactSlots
{
public:
  // Maximum number of walls one particle may touch at once.
  static constexpr int per_particle = 3;

  // All slots of `particles` particles free (no walls: no slots at all).
  void reset(std::size_t particles, std::size_t walls);
  bool empty() const { return wall_.empty(); }

  // Frees the slots of particle i whose wall is not among touching[0 .. m).
  void release_untouched(std::size_t i, const int *touching, int m);
  // The slot of particle i's contact with `wall`: the one it already has, else the first free
  // one (after release_untouched there always is one). Marks it taken by `wall`.
  std::size_t slot_for(std::size_t i, int wall);

  Vector3 history(std::size_t slot) const { return {hx_[slot], hy_[slot], hz_[slot]}; }
  // The wall slot `slot` (= particle × per_particle + k) is in contact with (−1: free).
  int wall(std::size_t slot) const { return wall_.empty() ? -1 : wall_[slot]; }
  void set_history(std::size_t slot, const Vector3 &xi) { hx_[slot] = xi.x, hy_[slot] = xi.y, hz_[slot] = xi.z; }
  void set_load(std::size_t slot, const Vector3 &force_on_wall, const Vector3 &torque_on_wall)
  {
    fx_[slot] = force_on_wall.x, fy_[slot] = force_on_wall.y, fz_[slot] = force_on_wall.z;
    tx_[slot] = torque_on_wall.x, ty_[slot] = torque_on_wall.y, tz_[slot] = torque_on_wall.z;
  }

  // Grows to `particles` particles, the new ones with all slots free (no history).
  void extend(std::size_t particles);

  // The particles were re-sorted (new[k] = old[order[k]]): the slots follow in blocks. An
  // order shorter than the particle count drops the slots of the particles it leaves out.
  void permute(const std::vector<std::int32_t> &order, std::vector<double> &scratch,
               std::vector<std::int32_t> &iscratch);

  // Loads summed per wall, and the contacts of one wall in particle order (`out` cleared).
  std::vector<WallLoad> loads(std::size_t walls) const;
  void contacts_of_wall(std::size_t w, std::vector<WallContactRecord> &out) const;

  void write(CheckpointWriter &out) const;
  void read(CheckpointReader &in);
  std::size_t memory_bytes() const;

private:
  bool has_walls_ = false;
  std::vector<std::int32_t> wall_;
  std::vector<std::int32_t> slot_order_; // permute()'s scratch
  std::vector<double> hx_, hy_, hz_;           // tangential history ξ
  std::vector<double> fx_, fy_, fz_, tx_, ty_, tz_; // load on the wall
  std::array<std::vector<double> *, 9> doubles() { return {&hx_, &hy_, &hz_, &fx_, &fy_, &fz_, &tx_, &ty_, &tz_}; }
  std::array<const std::vector<double> *, 9> doubles() const
  {
    return {&hx_, &hy_, &hz_, &fx_, &fy_, &fz_, &tx_, &ty_, &tz_};
  }
};

} // namespace magbrush::dem
