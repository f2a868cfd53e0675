// `magbrush mesh CASE [--set key=value ...] [-o DIR]`: write the Gmsh meshes of the roller
// (magnetostatics) and of the development nip (electrostatics) the field solver reads, and
// print per region the cells and the area against the exact area.
// Exit codes: 0 written, 1 invalid case or meshing failure, 2 usage error.
#include "app/subcommand.h"

#include "common/atomic_file.h"
#include "case/case_hash.h"
#include "case/case_parser.h"
#include "geometry/mesh_common.h"
#include "geometry/mesh_nip.h"
#include "geometry/mesh_roller.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

namespace {

// A mesh is up to date when it exists and the digest of the inputs it was written from
// (case/case_hash.h mesh_hash, stored next to it as <mesh>.inputs) equals the case's: then
// it is not rewritten (meshing the roller takes ~10 s). The reason for remeshing is printed.
std::string inputs_file(const std::string &mesh) { return mesh + ".inputs"; }

bool mesh_is_current(const std::string &mesh, const std::string &hash, std::string &reason)
{
  if (!std::filesystem::exists(mesh))
  {
    reason = "no mesh yet";
    return false;
  }
  std::ifstream in(inputs_file(mesh));
  std::string stored;
  if (!(in >> stored))
  {
    reason = "no record of the inputs it was written from (" + inputs_file(mesh) + ")";
    return false;
  }
  if (stored != hash)
  {
    reason = "its inputs changed (stored hash " + stored + ", case " + hash + ")";
    return false;
  }
  return true;
}

void record_inputs(const std::string &mesh, const std::string &hash)
{
  magbrush::write_file_atomically(inputs_file(mesh), [&](std::ostream &out) { out << hash << "\n"; });
}

// The options, declared once: the parser and `magbrush run` read them (common/command_line.h).
const magbrush::cli::CommandSpec &mesh_command_line()
{
  static const magbrush::cli::CommandSpec spec = [] {
    magbrush::cli::CommandSpec s;
    s.program = "magbrush mesh";
    s.usage = "magbrush mesh CASE.yaml [--set key=value ...] [-o DIR] [--only roller|nip] [--force]\n"
              "                    [--verbose] [--gui-free]";
    s.description =
        "Writes the quadrilateral meshes of the field solver's geometry for inspection in Gmsh (MSH 2.2\n"
        "ASCII, written atomically; the solver builds the same meshes itself, so no stage reads these):\n"
        "  DIR/roller.msh  shaft, magnet, sleeve wall, air, magnetic blades, open-boundary shell\n"
        "                  (needs roller and sleeve)\n"
        "  DIR/nip.msh     air, photoconductor layer, shell; sleeve, drum substrate and outer\n"
        "                  boundaries (needs drum.present)\n"
        "and prints, per region, the cells and the meshed area against the exact area, per boundary\n"
        "the faces and the length. Region and boundary tags are listed in geometry/mesh_tags.h.\n"
        "A mesh whose inputs did not change since it was written (DIR/<mesh>.inputs holds their\n"
        "digest) is not rewritten; --force remeshes.\n"
        "Element sizes: field.mesh_size_sleeve, field.mesh_size_gap, field.mesh_size_far; the shell\n"
        "starts at field.outer_radius_factor times the radius enclosing the scene.\n";
    s.positionals = {{"CASE.yaml", "the case file"}};
    s.options = {
        magbrush::cli::set_option("field.mesh_size_sleeve=0.2mm"),
        {"--output", {"-o"}, "DIR", "where to write (default: meshes/<case name>)", false, {}, /*for_pipeline=*/false},
        {"--only", {}, "roller|nip", "only the roller or only the nip mesh", false, {"roller", "nip"}, false},
        {"--verbose", {"-v"}, "", "show Gmsh's progress messages"},
        {"--force", {}, "", "remesh even when the stored mesh is up to date"},
        {"--gui-free", {}, "", "accepted for scripts; magbrush never opens the Gmsh GUI"}};
    s.examples = {{"magbrush mesh cases/kawamoto_nip_fed.yaml", "write meshes/kawamoto_nip_fed/{roller,nip}.msh"},
                  {"magbrush mesh cases/kawamoto_nip_fed.yaml --only roller --set field.mesh_size_sleeve=0.2mm",
                   "the roller's mesh only, finer at the sleeve"}};
    s.exit_status = "0 written, 1 invalid case or meshing failure, 2 usage error.";
    return s;
  }();
  return spec;
}

int mesh(const magbrush::cli::ParsedArguments &args)
{
  const std::string case_file = args.positional(0);
  const std::vector<std::string> overrides = args.values("--set");
  std::string output_dir = args.value("--output");
  const std::string only = args.value("--only");
  magbrush::MeshOptions options;
  options.verbose = args.has("--verbose");

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
    const std::string hash = magbrush::mesh_hash(c);
    const bool force = args.has("--force");
    // Writes one mesh unless it is up to date; says which and why.
    const auto write_unless_current = [&](const char *what, const std::string &path, auto write) {
      std::string reason;
      if (!force && mesh_is_current(path, hash, reason))
      {
        std::cout << what << " mesh: up to date (" << path << ", inputs hash " << hash << "): not remeshed\n\n";
        return;
      }
      // Forget the old record first: a run killed between the mesh and its record remeshes.
      std::filesystem::remove(inputs_file(path));
      std::cout << what << " mesh (" << (force ? std::string("--force") : reason) << ")\n"
                << magbrush::format_mesh_summary(write(path)) << "\n";
      record_inputs(path, hash);
    };
    if (want_roller && roller_possible)
      write_unless_current("roller", output_dir + "/roller.msh",
                           [&](const std::string &p) { return magbrush::write_roller_mesh(c, p, options); });
    else if (want_roller)
      std::cout << "roller mesh: skipped (the case has no roller)\n\n";
    if (want_nip && nip_possible)
      write_unless_current("nip", output_dir + "/nip.msh",
                           [&](const std::string &p) { return magbrush::write_nip_mesh(c, p, options); });
    else if (want_nip)
      std::cout << "nip mesh: skipped (no drum in the case)\n\n";
  }
  catch (const std::exception &e)
  {
    std::cerr << "magbrush mesh: " << c.source_file << ": " << e.what() << "\n";
    return 1;
  }
  std::cout << "meshes in " << output_dir << "/\n";
  return 0;
}

int run_mesh(const std::vector<std::string> &args)
{
  return magbrush::cli::run_command(mesh_command_line(), {args.begin() + 1, args.end()}, mesh);
}

const bool registered = magbrush::register_subcommand(
    {"mesh", "write the Gmsh meshes of the roller and the nip (quadrilaterals, MSH 2.2)", run_mesh,
     mesh_command_line, 20});

} // namespace
