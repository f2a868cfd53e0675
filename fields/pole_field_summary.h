// The sleeve-surface field of a case's pole model, as `magbrush check` prints it among the
// derived numbers: the normal flux density at each pole and at the nip from the exact
// multipole ring (multipole_ring.h, the solution the field solver is verified against), with
// the magnetic pressure B²/2μ0 it stands for.
#pragma once

#include "case/case_model.h"

#include <string>

namespace magbrush {

// Lines "  <pole> at <angle>: Bn = …, magnetic pressure B^2/2mu0 = …" under a heading, and the
// nip's Bn when the case has a drum; "" for a case without a roller or sleeve; a line saying
// why when the ring cannot be built from the case.
std::string format_pole_field(const Case &c);

} // namespace magbrush
