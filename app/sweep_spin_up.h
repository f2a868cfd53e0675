// One spin-up for every point of a sweep (`magbrush sweep ... --spin-up DURATION --settle DURATION`).
//
// Why: a supplied nip first has to build its brush (the bank of developer in front of the gap
// takes ~8 ms in Kweon's development scene), and that part of the run does not depend on the
// varied value when the value only acts on what the brush then does (a bias, a latent image).
// Building it once and forking every point from its checkpoint saves that time per point.
//
// What a fork costs in accuracy: the state at the fork carries the spin-up's history (the
// carriers in the brush were stripped of toner at the spin-up's bias, the drum elements in the
// nip developed at it). A point's averages must start only after that history has left the
// measured region: --settle is that time after the fork, and the point's
// development.average_from (and the other measurements' average_from) start no earlier than
// spin-up + settle. The sweep prints what the speeds give for the settle so that the user can
// check the choice; the points' steady-state verdicts then check it in the data.
//
// Layout: <sweep>/spin_up/ is a run of the case at the sweep's --set values (none of the varied
// ones) to t = DURATION; its dem/checkpoint.bin is what every point restarts from
// (--restart FILE --restart-anyway: the point's own case continues the state). A spin-up that
// finished with the same case is reused. Each point records in its sweep_point.csv which
// spin-up it came from (folder, duration, the spin-up's case digest).
#pragma once

#include "case/case_model.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace magbrush {

struct SweepSpinUp
{
  double duration = 0.0; // the spin-up's end time, the fork [s]
  double settle = 0.0;   // the points' transient after the fork [s]
  std::filesystem::path dir;
  std::string case_digest; // of the spin-up's case (the sweep's case at its --set values)

  std::filesystem::path checkpoint() const { return dir / "dem" / "checkpoint.bin"; }
  // The points average from here on [s].
  double averages_from() const { return duration + settle; }
};

// The spin-up of this sweep, or nothing without --spin-up. `base` is the sweep's case with its
// --set values. Refuses a spin-up not shorter than the run, a point's own --restart, and a
// settle that leaves nothing to average.
std::optional<SweepSpinUp> plan_spin_up(const std::string &spin_up_text, const std::string &settle_text,
                                        const Case &base, const std::filesystem::path &sweep_dir);

// What the speeds say about the settle, in words: a drum element's transit from the brush's
// entry to the measuring line, and a carrier's across the scene's window (the time it takes the
// spin-up's carriers to leave).
std::string settle_estimate(const Case &base);

// True when the spin-up has finished with this case (its checkpoint and its record are there).
bool spin_up_done(const SweepSpinUp &spin_up);

// The words for `magbrush run` that make a point a fork of the spin-up: the restart, and the
// average_from of every measurement the case runs moved to the end of the settle (where the
// case's own is earlier).
std::vector<std::string> fork_words(const SweepSpinUp &spin_up, const Case &point_case);

// The record of the spin-up in a point's sweep_point.csv: header cells and value cells.
std::string spin_up_header_cells();
std::string spin_up_cells(const std::optional<SweepSpinUp> &spin_up);

// Writes the spin-up's own record (after it ran).
void record_spin_up(const SweepSpinUp &spin_up, double run_time_s);

} // namespace magbrush
