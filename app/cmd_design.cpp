// `magbrush design poles|gap|bias ...`: the inverse questions. `design poles` finds the pole
// layout that meets a target sleeve profile or a specification (design_poles_command.h);
// `design gap` and `design bias` read a finished study and give the blade gap or the bias
// that reaches a target DMA or TMA, with its interval (design_study_command.h).
#include "app/design_poles_command.h"
#include "app/design_release_command.h"
#include "app/design_study_command.h"
#include "app/subcommand.h"

namespace magbrush {
namespace {

const cli::CommandSpec &design_command_line()
{
  static const cli::CommandSpec spec = [] {
    cli::CommandSpec s;
    s.program = "magbrush design";
    s.usage = "magbrush design poles CASE --target FILE [--constraints FILE] [--fix POLE,...] [options]\n"
              "       magbrush design gap  --target 0.40kg/m2 STUDY_DIR [--tolerance 5um [--refine]] [options]\n"
              "       magbrush design bias --target 0.5mg/cm2 STUDY_DIR [--tolerance 10V [--refine]] [options]\n"
              "       magbrush design release CASE [--vary key=v1,v2,...] [--window FROM,TO]";
    s.description = R"(The inverse of the analysis: what to build for a wanted result.

design poles: the pole layout (each pole's angle and strength; signs and shape factors stay
the case's) that meets a target, by bounded least squares on the exact multipole ring from
several starts. The target is a sleeve profile in the scan format of `magbrush flux` (angle,
Bn[, Bt]; optional columns weight and tolerance, e.g. tolerance_mT) or a specification in YAML
(per pole: peak |Bn| and its angle with tolerances; arcs where |B| must stay below a level;
an arc where the release criterion must let a carrier bead go; a minimum spacing;
constraints: per-pole bounds, fixed poles, the remanence limit); see
docs/design_tools.md. Prints the best layout, every requirement met or missed and by how much,
a sensitivity table (requirement per 1 deg / 10 kA/m of each pole), the binding constraints
when the target is infeasible, and checks the winner with the finite-element solver.

design gap | bias: reads a finished study (STUDY_DIR/sweep_mean.csv when there is one, else
sweep_summary.csv), interpolates the quantity (dma_kg_per_m2 for gap, tma_kg_per_m2 for bias)
against the varied value (blades.doctor.gap, electric.bias) — piecewise linear where the
means are monotone, a weighted straight line otherwise — and gives the value for the target
with its standard error propagated from the points'. A target outside the study's range is
reported as such (with the line's extrapolation, marked). With --tolerance: whether the 95 %
interval is within it and, if not, the one extra point that narrows it most; --refine runs that
point as a point of the study (its own sweep, extended: the same case and --set, the value
appended; then the study's tables are merged again) and repeats until the interval is within
the tolerance, --max-points have run, or one more point would narrow it by less than 10 %.

design release: the field criterion for release, from the exact ring in seconds: the outward
acceleration of a carrier bead at the sleeve, magnetic (3β/(2μ0ρ) ∂B²/∂r) plus centrifugal plus
gravity; held where it is negative. For the case's layout or each --vary value, ranked by the
largest net outward acceleration in the release window (dma.release_from → release_to, or
--window), with the arcs where a bead is no longer held.
)";
    s.positionals = {{"MODE", "poles, gap, bias or release"},
                     {"CASE|STUDY_DIR", "the case (poles, release) or the study folder (gap, bias)"}};
    s.options = {
        {"--target", {}, "FILE|VALUE", "poles: the target profile (CSV) or specification (YAML);\ngap, bias: the wanted value with its unit (0.40kg/m2)"},
        {"--constraints", {}, "FILE", "poles: a YAML file with a constraints: section"},
        {"--fix", {}, "POLE,...", "poles: poles that may not move or change", true},
        {"--max-strength", {}, "M", "poles: the remanence limit on every |M| (e.g. 400kA/m)"},
        {"--angle-range", {}, "ANGLE", "poles: default bound, each pole within ± this of the case's angle (30deg)"},
        {"--tolerance", {}, "B|VALUE", "poles: a profile sample's tolerance when its file has none (1mT);\ngap, bias: the interval half-width wanted (reported)"},
        {"--starts", {}, "N", "poles: least-squares starts (8: the case's layout and 7 random ones)"},
        {"--angle-unit", {}, "deg|rad", "poles: unit of a profile target's angle column"},
        {"--field-unit", {}, "T|mT|G|kG", "poles: unit of a profile target's Bn/Bt columns"},
        {"--no-fem-check", {}, "", "poles: skip the finite-element check of the designed layout"},
        {"--no-plot", {}, "", "poles: do not call tools/plot_design.py"},
        {"--output", {"-o"}, "DIR", "poles: output folder (default <output.directory>/design)", false, {}, false},
        cli::set_option("roller.poles.S2.angle=150deg"),
        {"--quantity", {}, "KEY", "gap, bias: the study's column (default dma_kg_per_m2 / tma_kg_per_m2)"},
        {"--key", {}, "KEY", "gap, bias: the varied column (default blades.doctor.gap / electric.bias)"},
        {"--table", {}, "FILE", "gap, bias: the study table to read (default: from STUDY_DIR)"},
        {"--vary", {}, "KEY=V1,V2", "release: one layout per value, ranked (e.g. roller.poles.S2.angle=144deg,165deg)"},
        {"--window", {}, "FROM,TO", "release: the window judged (default dma.release_from,release_to)"},
        {"--refine", {}, "", "gap, bias: run the extra points until the interval is within --tolerance"},
        {"--max-points", {}, "N", "gap, bias --refine: at most N extra points (3)"},
        {"--threads", {}, "N", "gap, bias --refine: the DEM threads of an extra point"},
        {"--skip", {}, "STAGE[,STAGE]", "gap, bias --refine: stages not run at an extra point (the sweep's default: mesh)"},
        {"--method", {}, "auto|piecewise|line", "gap, bias: interpolation (auto: piecewise where monotone)", false,
         {"auto", "piecewise", "line"}}};
    s.epilog = R"(Outputs of design poles in DIR: design_report.txt, <case>_designed.yaml, design_profile.csv
(the designed profile, and the FEM's), design_requirements.csv, design_sensitivity.csv,
design_bands.csv, design_profile.png, and the design's page index.html (index.md): the profile against
the target, the requirements, the layout and the sensitivities; the case's run report links it.
See docs/design_tools.md.
)";
    s.examples = {
        {"magbrush design poles cases/kweon_development.yaml --target cases/data/kweon_development_spec.yaml",
         "a layout meeting a specification (peaks, a low-field arc, spacing), checked by the FEM"},
        {"magbrush design poles cases/kweon_release.yaml --target cases/data/kweon_release_spec.yaml",
         "S2 alone moved so that the layer is let go between S2 and S3"},
        {"magbrush design release cases/kweon_release.yaml --vary roller.poles.S2.angle=144deg,155deg,165deg",
         "three layouts ranked by the field criterion for release"},
        {"magbrush design gap --target 0.40kg/m2 results/sweep_gap",
         "the blade gap for a DMA, read off the study of docs/regulation.md"},
        {"magbrush design gap --target 0.40kg/m2 results/sweep_gap --tolerance 5um --refine --threads 1",
         "the same, running extra points of the study until the 95 % interval is within 5 um"}};
    s.exit_status = "0 done (poles: every requirement met; gap/bias: the target within the study and, with\n"
                    "--tolerance, the interval within it), 1 bad input or a failed extra point, 2 bad usage,\n"
                    "3 the target cannot be met (poles: infeasible, nearest layout written) or lies outside the\n"
                    "study, 4 gap/bias with --tolerance: the interval is still wider than the tolerance.";
    return s;
  }();
  return spec;
}

int run_design(const std::vector<std::string> &args)
{
  return cli::run_command(design_command_line(), {args.begin() + 1, args.end()},
                          [](const cli::ParsedArguments &parsed) {
                            const std::string mode = parsed.positional(0);
                            if (parsed.positional(1).empty())
                              throw cli::UsageError("design " + mode + " needs " +
                                                    (mode == "gap" || mode == "bias" ? "a study folder" : "a case file"));
                            if (mode == "poles")
                              return run_design_poles(parsed);
                            if (mode == "gap" || mode == "bias")
                              return run_design_study(parsed, mode);
                            if (mode == "release")
                              return run_design_release(parsed);
                            throw cli::UsageError("unknown mode '" + mode + "' (poles, gap, bias or release)");
                          });
}

const bool registered = register_subcommand(
    {"design", "the inverse: pole layout, blade gap or bias that meets a target; release criterion", run_design,
     design_command_line, 55});

} // namespace
} // namespace magbrush
