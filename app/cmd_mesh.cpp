// `magbrush mesh CASE [--set key=value ...] [-o DIR]`: write the Gmsh meshes of the roller
// (magnetostatics) and of the development nip (electrostatics) the field solver reads, and
// print per region the cells and the area against the exact area.
// Exit codes: 0 written, 1 invalid case or meshing failure, 2 usage error.
#include "subcommand.h"

#include "case_parser.h"
#include "mesh_common.h"
#include "mesh_nip.h"
#include "mesh_roller.h"

#include <iostream>

namespace {

const char *usage =
    "Usage: magbrush mesh CASE.yaml [--set key=value ...] [-o DIR] [--only roller|nip]\n"
    "                    [--verbose] [--gui-free]\n\n"
    "Writes the quadrilateral meshes the field solver reads (MSH 2.2 ASCII, written atomically):\n"
    "  DIR/roller.msh  shaft, magnet, sleeve wall, air, magnetic blades, open-boundary shell\n"
    "                  (needs roller and sleeve)\n"
    "  DIR/nip.msh     air, photoconductor layer, shell; sleeve, drum substrate and outer\n"
    "                  boundaries (needs drum.present)\n"
    "and prints, per region, the cells and the meshed area against the exact area, per boundary\n"
    "the faces and the length. Region and boundary tags are listed in geometry/mesh_tags.h.\n"
    "Element sizes: field.mesh_size_sleeve, field.mesh_size_gap, field.mesh_size_far; the shell\n"
    "starts at field.outer_radius_factor times the radius enclosing the scene.\n\n"
    "  --set key=value  override a case key (e.g. --set field.mesh_size_sleeve=0.2mm)\n"
    "  -o, --output DIR where to write (default: meshes/<case name>)\n"
    "  --only WHICH     only the roller or only the nip mesh\n"
    "  --verbose        show Gmsh's progress messages\n"
    "  --gui-free       accepted for scripts; magbrush never opens the Gmsh GUI\n\n"
    "Exit status: 0 written, 1 invalid case or meshing failure, 2 usage error.\n";

int usage_error(const std::string &message)
{
  std::cerr << "magbrush mesh: " << message << "\n\n" << usage;
  return 2;
}

int run_mesh(const std::vector<std::string> &args)
{
  std::string case_file, output_dir, only;
  std::vector<std::string> overrides;
  magbrush::MeshOptions options;
  for (size_t i = 1; i < args.size(); ++i)
  {
    const std::string &a = args[i];
    auto value = [&](const std::string &what) -> const std::string * {
      if (i + 1 >= args.size())
        return nullptr;
      (void)what;
      return &args[++i];
    };
    if (a == "--help" || a == "-h")
    {
      std::cout << usage;
      return 0;
    }
    if (a == "--set" || a == "-s")
    {
      const std::string *v = value("key=value");
      if (!v)
        return usage_error("--set needs key=value (e.g. --set field.mesh_size_far=3mm)");
      overrides.push_back(*v);
    }
    else if (a.rfind("--set=", 0) == 0)
      overrides.push_back(a.substr(6));
    else if (a == "-o" || a == "--output")
    {
      const std::string *v = value("directory");
      if (!v)
        return usage_error(a + " needs a directory");
      output_dir = *v;
    }
    else if (a == "--only")
    {
      const std::string *v = value("roller|nip");
      if (!v || (*v != "roller" && *v != "nip"))
        return usage_error("--only needs 'roller' or 'nip'");
      only = *v;
    }
    else if (a == "--verbose" || a == "-v")
      options.verbose = true;
    else if (a == "--gui-free")
      ; // never a GUI
    else if (!a.empty() && a[0] == '-')
      return usage_error("unknown option '" + a + "'");
    else if (case_file.empty())
      case_file = a;
    else
      return usage_error("more than one case file given ('" + case_file + "' and '" + a + "')");
  }
  if (case_file.empty())
    return usage_error("no case file given");

  magbrush::Case c;
  try
  {
    c = magbrush::load_case(case_file, overrides);
  }
  catch (const magbrush::CaseError &e)
  {
    std::cerr << "magbrush mesh: " << e.what() << "\n";
    return 1;
  }
  if (output_dir.empty())
    output_dir = "meshes/" + c.name;

  const bool roller_possible = c.roller && c.sleeve, nip_possible = c.sleeve && c.drum.present;
  const bool want_roller = only.empty() || only == "roller", want_nip = only.empty() || only == "nip";
  if ((want_roller && !roller_possible && !only.empty()) || (want_nip && !nip_possible && !only.empty()) ||
      (!roller_possible && !nip_possible))
  {
    std::cerr << "magbrush mesh: " << c.source_file << " has nothing to mesh"
              << (only.empty() ? "" : " for --only " + only)
              << ": the roller mesh needs `roller` and `sleeve`, the nip mesh a `drum` (scene '" << c.scene
              << "')\n";
    return 1;
  }
  try
  {
    if (want_roller && roller_possible)
      std::cout << "roller mesh\n"
                << magbrush::format_mesh_summary(magbrush::write_roller_mesh(c, output_dir + "/roller.msh", options))
                << "\n";
    else if (want_roller)
      std::cout << "roller mesh: skipped (the case has no roller)\n\n";
    if (want_nip && nip_possible)
      std::cout << "nip mesh\n"
                << magbrush::format_mesh_summary(magbrush::write_nip_mesh(c, output_dir + "/nip.msh", options))
                << "\n";
    else if (want_nip)
      std::cout << "nip mesh: skipped (no drum in the case)\n\n";
  }
  catch (const std::exception &e)
  {
    std::cerr << "magbrush mesh: " << c.source_file << ": " << e.what() << "\n";
    return 1;
  }
  std::cout << "meshes written to " << output_dir << "/\n";
  return 0;
}

const bool registered = magbrush::register_subcommand(
    {"mesh", "write the Gmsh meshes of the roller and the nip (quadrilaterals, MSH 2.2)", run_mesh, 20});

} // namespace
