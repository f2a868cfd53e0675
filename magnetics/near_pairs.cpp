#include "magnetics/near_pairs.h"

namespace magbrush::magnetics {

namespace {
void store_tensor(const DipoleTensor &T, double *t)
{
  t[0] = T.xx;
  t[1] = T.yy;
  t[2] = T.zz;
  t[3] = T.xy;
  t[4] = T.xz;
  t[5] = T.yz;
}
} // namespace

std::size_t NearPairs::evaluate_tensors(const BeadArrays &beads, double cutoff)
{
  const std::size_t np = list_.pairs().size();
  tensor_.resize(np);
  r_.resize(3 * np);
  active_.resize(np);
  cutoff_ = cutoff;
  std::size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) if (np >= bead_parallel_threshold)
  for (long k = 0; k < static_cast<long>(np); ++k)
  {
    evaluate_tensor(beads, k);
    count += active_[k];
  }
  return count;
}

void NearPairs::evaluate_tensor(const BeadArrays &beads, std::size_t k)
{
  const auto &p = list_.pairs()[k];
  double r[3] = {beads.x[p.j] - beads.x[p.i] + p.shift[0],
                 beads.y[p.j] - beads.y[p.i] + p.shift[1],
                 beads.z[p.j] - beads.z[p.i] + p.shift[2]};
  const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  for (int d = 0; d < 3; ++d)
    r_[3 * k + d] = r[d];
  // Hard cutoff (as Kawamoto): pairs beyond it do not interact at all. Coincident
  // centres (r = 0) cannot occur between non-overlapping beads; they are skipped.
  active_[k] = (r2 < cutoff_ * cutoff_ && r2 > 0.0);
  if (active_[k])
    tensor_[k] = DipoleTensor::at(r);
  else
    tensor_[k] = {0, 0, 0, 0, 0, 0};
}

void NearPairs::appended(const BeadArrays &beads, std::size_t first_pair)
{
  const std::size_t np = list_.pairs().size();
  tensor_.resize(np);
  r_.resize(3 * np);
  active_.resize(np);
  for (std::size_t k = first_pair; k < np; ++k)
    evaluate_tensor(beads, k);
  // The rows are left as they are, out of date (has_rows() is false now): rebuilding them is
  // O(pairs) for the few dozen beads of an admission (it was ~12 % of a full-roller run). The
  // sweeps read the partners through the list until the next full evaluation builds them.
}

void NearPairs::update_rows(std::size_t k)
{
  if (row_entry_.size() != 2 * list_.pairs().size())
    return; // no rows (hard cutoff)
  for (int side = 0; side < 2; ++side)
    store_tensor(tensor_[k], &row_tensor_[6 * row_entry_[2 * k + side]]);
}

void NearPairs::build_rows()
{
  const auto &begin = list_.incident_begin();
  const auto &end = list_.incident_end();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  const auto &pairs = list_.pairs();
  const std::size_t n = end.size();
  // The rows are packed (the list's spare slots left out): a sweep streams through them.
  row_begin_.resize(n + 1);
  row_begin_[0] = 0;
  for (std::size_t b = 0; b < n; ++b)
    row_begin_[b + 1] = row_begin_[b] + (end[b] - begin[b]);
  row_other_.resize(row_begin_[n]);
  row_tensor_.resize(6 * row_begin_[n]);
  // Where each pair sits in the two beads' rows (a self-image pair twice in one row, once per
  // end): every (pair, end) slot is written by exactly one row.
  row_entry_.resize(2 * pairs.size());
#pragma omp parallel for schedule(static) if (n >= bead_parallel_threshold)
  for (long b = 0; b < static_cast<long>(n); ++b)
    for (std::size_t q = begin[b]; q < end[b]; ++q)
    {
      const std::size_t e = row_begin_[b] + (q - begin[b]);
      const std::uint32_t k = pair_of[q];
      row_entry_[2 * k + (first[q] ? 0 : 1)] = e;
      row_other_[e] = first[q] ? pairs[k].j : pairs[k].i;
      store_tensor(tensor_[k], &row_tensor_[6 * e]); // zero for an inactive (coincident) pair
    }
}

void NearPairs::add_row_field(std::size_t b, const std::vector<double> &p, double s[3]) const
{
  double sx = s[0], sy = s[1], sz = s[2];
  const std::size_t q0 = row_begin_[b], q1 = row_begin_[b + 1];
  const std::uint32_t *other = row_other_.data();
  const double *t = row_tensor_.data();
  for (std::size_t q = q0; q < q1; ++q)
  {
    const double *pk = &p[3 * other[q]];
    const double *T = &t[6 * q];
    sx += T[0] * pk[0] + T[3] * pk[1] + T[4] * pk[2];
    sy += T[3] * pk[0] + T[1] * pk[1] + T[5] * pk[2];
    sz += T[4] * pk[0] + T[5] * pk[1] + T[2] * pk[2];
  }
  s[0] = sx;
  s[1] = sy;
  s[2] = sz;
}

void NearPairs::add_row_field_through_list(std::size_t b, const std::vector<double> &p, double s[3]) const
{
  // add_row_field() term for term (every pair, an inactive one's zero tensor included, in
  // the same order with the same arithmetic), so that a sweep gives the same bits either way.
  const auto &begin = list_.incident_begin();
  const auto &end = list_.incident_end();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  const auto &pairs = list_.pairs();
  double sx = s[0], sy = s[1], sz = s[2];
  for (std::size_t q = begin[b]; q < end[b]; ++q)
  {
    const std::uint32_t k = pair_of[q];
    const double *pk = &p[3 * (first[q] ? pairs[k].j : pairs[k].i)];
    const DipoleTensor &T = tensor_[k];
    sx += T.xx * pk[0] + T.xy * pk[1] + T.xz * pk[2];
    sy += T.xy * pk[0] + T.yy * pk[1] + T.yz * pk[2];
    sz += T.xz * pk[0] + T.yz * pk[1] + T.zz * pk[2];
  }
  s[0] = sx;
  s[1] = sy;
  s[2] = sz;
}

void NearPairs::add_list_field(std::size_t b, const std::vector<double> &p, double B[3]) const
{
  const auto &begin = list_.incident_begin();
  const auto &end = list_.incident_end();
  const auto &pair_of = list_.incident_pair();
  const auto &first = list_.incident_first();
  const auto &pairs = list_.pairs();
  for (std::size_t q = begin[b]; q < end[b]; ++q)
  {
    const std::uint32_t k = pair_of[q];
    if (!active_[k])
      continue;
    const std::uint32_t other = first[q] ? pairs[k].j : pairs[k].i;
    tensor_[k].add_field(&p[3 * other], B);
  }
}

void NearPairs::write_state(StateOut &out) const
{
  list_.write_state(out);
  out.put(cutoff_);
  out.put_array(tensor_);
  out.put_array(r_);
  out.put_array(active_);
  out.put<std::uint8_t>(has_rows());
}

void NearPairs::read_state(StateIn &in)
{
  list_.read_state(in);
  cutoff_ = in.get<double>();
  in.get_array(tensor_);
  in.get_array(r_);
  in.get_array(active_);
  if (tensor_.size() != list_.pairs().size() || r_.size() != 3 * tensor_.size() || active_.size() != tensor_.size())
    in.fail("is corrupt (magnetic near pairs: " + std::to_string(list_.pairs().size()) + " pairs, " +
            std::to_string(tensor_.size()) + " tensors)");
  const bool rows = in.get<std::uint8_t>() != 0;
  row_begin_.clear();
  row_other_.clear();
  row_tensor_.clear();
  row_entry_.clear();
  if (rows)
    build_rows(); // copies of the tensors, in the list's incidence order
}

} // namespace magbrush::magnetics
