// Case keys of module "output" (the list of modules and why it is explicit: case_keys.h).
// Where results go and in which formats. Read by the driver (stage logs, the report) and by
// dem/ (snapshots).
#include "case/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> output_keys()
{
  return {
      section("output", "Results."),
      text("output.directory",
           "Results directory (empty: results/<name>, and results/<name>-<6 hex digits> for a run with --set "
           "overrides: the digest of the sorted overrides, listed in its variant.txt).")
          .def(""),
      boolean("output.vtu", "Also write VTK XML particle snapshots (snapshots/*.vtu, index particles.pvd).").def("false"),
      boolean("output.xdmf", "Write HDF5 particle snapshots with their XDMF index (particles.xdmf).").def("true"),
  };
}

} // namespace magbrush::case_keys
