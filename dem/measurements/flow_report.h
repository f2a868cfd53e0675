// The flow report of a scene with particles entering and leaving (case keys flow_report.*):
// one row per sample in flow_report.csv with
//
//  * in: particles and mass created by the inflow so far (its own counters), and the mass it
//    owes for the sleeve's rotation so far, Γ R φ(t) L_z (created follows it within a particle);
//  * out: particles and mass removed by the outflow so far (its own counters);
//  * present: particles and mass in the scene now, summed from the particle state.
//    The budget reads in − out = present − present(0): three independent counts;
//    With a sump inflow (inflow.supply: sump), due − declined is what the inflow was to create;
//  * the flux through the radial line flow_report.flux_angle since the previous sample and the
//    areal mass around the line (line_flux.h), counted from positions alone.
//
// The engine's own counts of particles that entered and left are in the log.
//
// Its summary (summary.csv, what a study tabulates), over the samples at t >= flow_report.average_from:
//  * supplied_flux_kg_per_m2: the mass flux through the line over (sleeve speed x slab), the
//    developer mass per sleeve area the flow carries past it (the DMA in its flux form);
//  * supplied_areal_mass_kg_per_m2: the areal mass around the line (the DMA in its areal form);
//  * inflow_declined_fraction: the part of a sump's offer that found no room in the entry arc
//    (a pile backed up to the inflow: then the supplied mass is measured, not set).
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/line_flux.h"
#include "dem/measurements/sample_series.h"

#include "case/case_model.h"

#include <string>
#include <vector>

namespace magbrush::dem {

struct FlowReportRow
{
  double time = 0.0;
  long in = 0, out = 0, present = 0;
  double in_mass = 0.0, due_mass = 0.0, out_mass = 0.0, present_mass = 0.0; // [kg]
  double crossed_mass = 0.0; // through the flux line since the previous row [kg]
  long crossed = 0;
  double flux = 0.0;         // crossed_mass / time since the previous row [kg/s]
  double areal_mass = 0.0;   // around the flux line [kg/m²]
  double declined_mass = 0.0; // offered by a sump inflow and left there for want of room so far [kg]
  double sump_mass = 0.0;     // a finite sump's stock [kg] (NaN: the sump is unlimited)
};

class FlowReport : public Measurement
{
public:
  explicit FlowReport(const Case &c);

  const char *name() const override { return "flow report"; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;
  std::vector<SummaryValue> summary() const override;

  const std::vector<FlowReportRow> &rows() const { return rows_; }
  std::string csv() const;

private:
  FlowSettings settings_;
  StatisticsSettings statistics_;
  double sleeve_speed_ = 0.0, slab_ = 0.0;
  LineFlux flux_;
  std::vector<FlowReportRow> rows_;
  // The summary's samples (t >= average_from) and the first row in that window.
  SampleSeries supplied_flux_, supplied_areal_;
  long window_first_row_ = -1;
  bool sump_ = false;
};

} // namespace magbrush::dem
