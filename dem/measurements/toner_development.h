// Toner development onto the photoreceptor (Kweon et al. Fig. 8–9): how much toner the drum
// carries away from the nip, on the image and on the background, with what charge, and how
// close that comes to the limit the latent image sets.
//
// The latent image moves with the drum surface (drum_image.h: its strips in the drum's frame).
//
// Every sample it takes THE TONER ON THE DRUM'S LAYER: the toner touching the drum (its wall
// contacts) and the toner resting on those, layer on layer (touching, or within the adhesion
// range of, a toner of the layer below, and held by no carrier: toner on a carrier is in the
// brush). A tape lift takes the stacked toner too; the contacts alone would miss it. Then
//  * in the MEASURING WINDOW downstream of the nip (nip coordinate x from development.measure_from
//    to development.measure_to, where the drum has left the brush): the toner mass per area on
//    the exposed strips (TMA, the image) and on the dark strips (fog), the developed charge per
//    mass, and the NEUTRALISATION RATIO σ_dev / (ε0 εr ΔV / L): the developed charge per area
//    against the charge that cancels the development contrast ΔV across the photoconductor
//    (thickness L, εr) — 1 is the physical limit of development, where
//        TMA_bound = ε0 εr ΔV / (L |q/m|);
//  * with development.average_over = image_periods, the same four over WHOLE PERIODS of the
//    latent image, each drum element counted once as it crosses measure_to (developed_line.h):
//    the summary's means are then those of the periods, which are its blocks (standard error,
//    steady-state test), and the developed profile across a strip is written. A moving image's
//    TMA in a fixed window repeats with the image's period, so a mean over a window of samples
//    depends on its phase unless it spans whole periods. On a uniform image (a solid area, or a
//    dark drum for the fog) the blocks are development.block_length of drum. The same count at
//    measure_from gives the TMA there (tma_at_measure_from_kg_per_m2): equal to the one at
//    measure_to within the errors where the brush has ended before measure_from;
//  * along the whole nip: where toner ARRIVES on the drum's layer (not on it at the previous
//    sample, on it now) and leaves it again, per bin of x, and the transfer rate per slab depth;
//  * in the whole scene: the share of the toner mass that sits on a carrier (within the adhesion
//    range of one), the developer's hold on its toner — toner that leaves its carrier before the
//    nip develops as a free cloud, whatever the contrast.
// ΔV = |V_bias − V_exposed|; for an image given as surface charges, V_exposed = σ L/(ε0 εr),
// the potential of the charged layer on its grounded substrate.
//
// Writes toner_development.csv (one row per sample), toner_transfer_profile.csv, with
// image_periods toner_developed_periods.csv, toner_developed_profile.csv and
// toner_developed_periods_at_measure_from.csv, and the key
// numbers with standard errors for the study table (summary()).
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/developed_line.h"
#include "dem/measurements/drum_image.h"
#include "dem/measurements/nip_frame.h"
#include "dem/measurements/sample_series.h"

#include "case/case_model.h"
#include "dem/wall_contact_slots.h"

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace magbrush::dem {

// One toner particle on the drum's layer at one sample.
struct DrumToner
{
  std::int32_t id = 0;
  double x = 0, y = 0;       // centre in the x-y plane [m]
  double mass = 0, charge = 0;
  int layer = 1;             // 1: touching the drum; 2, 3, ...: resting on the layer below
};

class TonerDevelopment : public Measurement
{
public:
  explicit TonerDevelopment(const Case &c);
  // The scene calls for it: a nip (sleeve, drum, slab), a nip field and a toner population.
  static bool applies(const Case &c);

  const char *name() const override { return "toner development"; }
  // 2: the toner on the carriers; 3: stacked toner counted, the developed line
  int state_version() const override { return 4; }
  double interval() const override { return settings_.sample_interval; }
  void sample(const DemSystem &system) override;
  void write(const std::string &directory) const override;
  void write_state(StateOut &out) const override;
  void read_state(StateIn &in) override;
  std::vector<SummaryValue> summary() const override;

  // The same from hand-made records (what sample() extracts from the engine); `on_carriers`:
  // the toner mass on carriers / all toner mass (NaN: not known).
  void add_sample(double time, const std::vector<DrumToner> &on_drum,
                  double on_carriers = std::numeric_limits<double>::quiet_NaN());
  // Per particle, `on` = 1 for a toner held by a carrier: within the adhesion range of one (its
  // touching pairs, when the contacts do not attract), from the neighbour list's pairs.
  // `is_toner`, `is_carrier`: per species.
  static void mark_on_carriers(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                               const std::vector<std::uint8_t> &is_carrier, std::vector<std::uint8_t> &on);
  // The toner mass held by a carrier (`on`, from mark_on_carriers) over all toner mass; toner a
  // carrier carries as its own mass (carried_until_gap) counts as on it.
  static double toner_share_on_carriers(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                                        const std::vector<std::uint8_t> &on);
  // The drum's layer: `layer` (per particle) holds 1 for the toner touching the drum and 0 else;
  // on return 2, 3, ... (up to max_layers) mark the toner resting on the layer below, held by no
  // carrier (`on_carrier`, from mark_on_carriers; pairs touching or within the adhesion range).
  static void stack_on_drum(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                            const std::vector<std::uint8_t> &on_carrier, std::vector<std::uint8_t> &layer);
  static constexpr int max_layers = 8;

  double contrast_potential() const { return contrast_; } // ΔV [V]
  double tma_bound() const;                                // [kg/m²]
  const SampleSeries &tma() const { return tma_; }
  const SampleSeries &fog() const { return fog_; }
  const SampleSeries &neutralisation() const { return ratio_; }
  const SampleSeries &on_carriers() const { return on_carriers_; }

  std::string csv() const;
  std::string transfer_profile_csv() const;
  // The developed line (average_over = image_periods), else null.
  const DevelopedLine *developed_line() const { return line_ ? &*line_ : nullptr; }
  const DevelopedLine *developed_line_at_measure_from() const { return near_line_ ? &*near_line_ : nullptr; }

private:
  DevelopmentSettings settings_;
  StatisticsSettings statistics_;
  NipFrame frame_;
  DrumImage image_;
  double eps_layer_over_l_ = 0.0; // ε0 εr / L [F/m²]
  double contrast_ = 0.0;         // ΔV [V]
  double toner_q_over_m_ = 0.0;   // the toner population's mean q/m [C/kg]
  double bin_width_ = 0.0;
  int bins_half_ = 0;
  std::vector<DrumToner> before_;      // the toner on the drum at the previous sample, by id
  std::vector<double> arrived_, left_; // toner mass arriving on / leaving the drum per bin [kg]
  double previous_time_ = -1.0, first_time_ = -1.0, last_time_ = -1.0;
  SampleSeries tma_, fog_, q_over_m_, ratio_, transfer_, on_carriers_;
  struct Row
  {
    double time, tma, fog, q_over_m, ratio, transfer, on_carriers;
    long image_toner, dark_toner, stacked_toner;
  };
  std::vector<Row> rows_; // every sample since the start
  // A row from average_from on into the means (its transfer when the interval before it is
  // inside the averaging window too).
  void add_to_means(const Row &row, bool with_transfer);
  // The summary over whole image periods (average_over = image_periods).
  std::vector<SummaryValue> period_summary() const;
  std::vector<SummaryValue> near_line_summary() const;
  // The developed line at measure_to (the TMA), and the same count at measure_from (whether the
  // layer is already complete there).
  std::optional<DevelopedLine> line_, near_line_;
  std::vector<LineToner> line_toner_;
  std::vector<WallContactRecord> records_;
  std::vector<DrumToner> toner_;
  std::vector<std::uint8_t> is_toner_, is_carrier_; // by species
  std::vector<std::uint8_t> layer_;                 // by particle: on the drum's layer (stack_on_drum)
  std::vector<std::uint8_t> on_carrier_;            // by particle: held by a carrier (mark_on_carriers)
};

} // namespace magbrush::dem
