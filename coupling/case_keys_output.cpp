// Case keys of module "output" (the list of modules and why it is explicit: case_keys.h).
// Where results go and in which formats. Read by the driver (stage logs, the report) and by
// dem/ (snapshots).
#include "coupling/case_keys.h"

namespace magbrush::case_keys {

std::vector<KeySpec> output_keys()
{
  return {
      section("output", "Results."),
      text("output.directory", "Results directory.").def("results"),
      boolean("output.vtu", "Write VTU particle snapshots.").def("true"),
      boolean("output.xdmf", "Write HDF5/XDMF particle snapshots.").def("true"),
  };
}

} // namespace magbrush::case_keys
