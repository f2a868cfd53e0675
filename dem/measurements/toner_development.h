// Toner development onto the photoreceptor (Kweon et al. Fig. 8–9): how much toner the drum
// carries away from the nip, on the image and on the background, with what charge, and how
// close that comes to the limit the latent image sets.
//
// The latent image moves with the drum surface. Its strips are those of the field stage
// (field_solver/nip_electrostatics.h latent_image_value): along the drum surface arc s, counted
// counter-clockwise about the drum centre from the nip point, exposed where
// frac(s/period + duty/2) < duty (an exposed strip centred on the nip at t = 0). A point of the
// drum surface moves with s(t) = s₀ + ω_d R_d t, so the image seen in the drum's own frame is
// fixed at s_drum = s − ω_d R_d t.
//
// Every sample it takes the toner touching the drum (its wall contacts) and
//  * in the MEASURING WINDOW downstream of the nip (nip coordinate x from development.measure_from
//    to development.measure_to, where the drum has left the brush): the toner mass per area on
//    the exposed strips (TMA, the image) and on the dark strips (fog), the developed charge per
//    mass, and the NEUTRALISATION RATIO σ_dev / (ε0 εr ΔV / L): the developed charge per area
//    against the charge that cancels the development contrast ΔV across the photoconductor
//    (thickness L, εr) — 1 is the physical limit of development, where
//        TMA_bound = ε0 εr ΔV / (L |q/m|);
//  * along the whole nip: where toner ARRIVES on the drum (not touching at the previous sample,
//    touching now) and leaves it again, per bin of x, and the transfer rate per slab depth;
//  * in the whole scene: the share of the toner mass that sits on a carrier (within the adhesion
//    range of one), the developer's hold on its toner — toner that leaves its carrier before the
//    nip develops as a free cloud, whatever the contrast.
// ΔV = |V_bias − V_exposed|; for an image given as surface charges, V_exposed = σ L/(ε0 εr),
// the potential of the charged layer on its grounded substrate.
//
// Writes toner_development.csv (one row per sample), toner_transfer_profile.csv, and the key
// numbers with standard errors for the study table (summary()).
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/nip_frame.h"
#include "dem/measurements/sample_series.h"

#include "coupling/case_model.h"
#include "dem/wall_contact_slots.h"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace magbrush::dem {

// One toner particle touching the drum at one sample.
struct DrumToner
{
  std::int32_t id = 0;
  double x = 0, y = 0;       // centre in the x-y plane [m]
  double mass = 0, charge = 0;
};

// The latent image strips in the drum's own frame.
class DrumImage
{
public:
  DrumImage(const LatentImage &image, const NipFrame &frame);
  // The arc coordinate of a point in the drum's frame at time t [m].
  double drum_arc(double px, double py, double t) const;
  bool exposed(double s_drum) const;
  // Exposed length of the drum-frame arc interval [a, b] [m] (a ≤ b).
  double exposed_length(double a, double b) const;

private:
  double period_, duty_;
  NipFrame frame_;
  double nip_angle_; // angle at the drum centre of the nip point (towards the sleeve) [rad]
};

class TonerDevelopment : public Measurement
{
public:
  explicit TonerDevelopment(const Case &c);
  // The scene calls for it: a nip (sleeve, drum, slab), a nip field and a toner population.
  static bool applies(const Case &c);

  const char *name() const override { return "toner development"; }
  int state_version() const override { return 2; } // 2: the toner on the carriers
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
  // The toner mass within the adhesion range of a carrier (its touching pairs, when the
  // contacts do not attract) over all toner mass, from the neighbour list's pairs; toner a
  // carrier carries as its own mass (carried_until_gap) counts as on it.
  static double toner_share_on_carriers(const DemSystem &system, const std::vector<std::uint8_t> &is_toner,
                                        const std::vector<std::uint8_t> &is_carrier);

  double contrast_potential() const { return contrast_; } // ΔV [V]
  double tma_bound() const;                                // [kg/m²]
  const SampleSeries &tma() const { return tma_; }
  const SampleSeries &fog() const { return fog_; }
  const SampleSeries &neutralisation() const { return ratio_; }
  const SampleSeries &on_carriers() const { return on_carriers_; }

  std::string csv() const;
  std::string transfer_profile_csv() const;

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
    long image_toner, dark_toner;
  };
  std::vector<Row> rows_; // every sample since the start
  // A row from average_from on into the means (its transfer when the interval before it is
  // inside the averaging window too).
  void add_to_means(const Row &row, bool with_transfer);
  std::vector<WallContactRecord> records_;
  std::vector<DrumToner> toner_;
  std::vector<std::uint8_t> is_toner_, is_carrier_; // by species
};

} // namespace magbrush::dem
