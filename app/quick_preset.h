// `magbrush run --quick`: a first look at a case in about a minute. The run is shortened to
// quick_duration of simulated time and every time that is measured from the start of the run
// — each measurement's averaging window (nip, development, dma, flow_report .average_from),
// the sleeve's and the drum's spin-up, the applied field's ramp — is scaled by the same
// factor, so that the windows keep their place in the run (a window that began at a third of
// the run still does) and the `check` stage's window tests still pass. Sample intervals, the
// time step, the settling time and the snapshot interval are kept: they are set by the
// physics or the output, not by the run's length.
//
// The changes are --set overrides: they name the run's folder like any variant, list
// themselves in its variant.txt, and leave the stored fields shared with the full run.
#pragma once

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush {

// 5 ms of simulated time: ~50 s of DEM for the default case on 2 cores (about 10 s per ms).
constexpr double quick_duration = 5e-3;

struct QuickChange
{
  std::string key;      // "nip.average_from"
  double from = 0, to = 0; // [s]
  std::string override_text() const; // "nip.average_from=1.66667 ms"
};

// The changes --quick makes to case `c`; none when the case already runs no longer than
// quick_duration (or sets no duration).
std::vector<QuickChange> quick_preset(const Case &c);

// One line per change, for the terminal: "  dem.duration 75 ms -> 5 ms (x 0.0667)".
std::string describe(const std::vector<QuickChange> &changes);

// What the preset leaves as it is and the user should know: a wall's prescribed path (a
// plate's protocol) keeps its times, so a shortened run stops part-way through it. "" if none.
std::string quick_caveats(const Case &c, const std::vector<QuickChange> &changes);

} // namespace magbrush
