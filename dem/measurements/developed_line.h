// The developed image as the page gets it: every element of the drum surface counted once, as it
// crosses a line after the nip, with the toner it carries then; summed over whole periods of
// the latent image.
//
// Why not the toner in a fixed window at each sample: the image moves through the window, and
// a window shorter than a strip sees part of one strip at a time, unevenly developed (most toner
// where the strip first met the brush). The window's mean then repeats with the image period
// (2 mm at 0.267 m/s: 7.5 ms in Kweon's case), and an average over part of a period depends on
// the phase it starts at: its two halves differ however long the run has been steady.
//
// Here, in the drum's frame (drum_image.h): the line at nip coordinate x_L is at drum arc
// s_L(t) = s_L,lab − ω_d R_d t. Between two samples the drum elements in [s_L(t₁), s_L(t₀)]
// cross it; the toner then on the drum's layer whose drum arc lies in that interval is counted
// (each toner once: ids counted are remembered while they stay on the drum, so that one sliding
// back over the line is not counted again). The areas are the swept arcs × the slab depth,
// split exactly into image and background by the strips, and into phase bins. A PERIOD closes
// when the swept arc reaches one image period (an interval that straddles the boundary is split
// at it, its toner by where it lies): every phase of the image is then counted exactly once, so
// a period's image TMA (its image mass / its image area) does not depend on where it started.
// The periods are the blocks of the statistics (toner_development.h); the phase bins of the
// whole periods give the developed profile across a strip (edges against centre).
#pragma once

#include "dem/measurement.h"
#include "dem/measurements/drum_image.h"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace magbrush::dem {

// One toner on the drum's layer as the line sees it.
struct LineToner
{
  std::int32_t id = 0;
  double s = 0;              // drum-frame arc of its centre [m]
  double mass = 0, charge = 0;
};

class DevelopedLine
{
public:
  // The blocks are the image's periods; a uniform image (a solid area or a dark drum) has none,
  // and `block_length` [m] gives them. `phase_bins` bins per block for the profile.
  DevelopedLine(const DrumImage &image, double slab_depth, int phase_bins, double block_length = 0.0);

  // One sample at `time`: `s_line` the drum-frame arc at the line now, `on_drum` the toner on the
  // drum's layer, sorted by id. The interval since the previous sample is counted when both
  // samples are `counting` (the averaging window); before it only the line's place is kept.
  void add_sample(double time, double s_line, const std::vector<LineToner> &on_drum, bool counting);

  // A whole image period past the line.
  struct Period
  {
    double t_start = 0, t_end = 0;         // when its first and last element crossed [s]
    double s_start = 0;                    // the drum arc of its first element [m]
    double image_mass = 0, image_area = 0; // [kg], [m²]
    double image_charge = 0;               // [C]
    double dark_mass = 0, dark_area = 0;
    long image_toner = 0, dark_toner = 0;
    // Toner mass per area on the image (TMA) and on the background (fog); NaN without that area
    // (the background of a solid area, the image of a dark drum).
    double tma() const { return image_area > 0.0 ? image_mass / image_area : std::numeric_limits<double>::quiet_NaN(); }
    double fog() const { return dark_area > 0.0 ? dark_mass / dark_area : std::numeric_limits<double>::quiet_NaN(); }
  };
  const std::vector<Period> &periods() const { return periods_; }
  // A uniform image's block by its place on the drum: blocks of two lines with the same index
  // hold the same drum elements (the grid is fixed to the drum; align_to_grid).
  long grid_index(const Period &p) const;
  // The arc swept so far into the period not yet closed [m].
  double open_period_length() const { return swept_; }

  // One bin of the developed profile across the image period, summed over the whole periods.
  struct Bin
  {
    double length = 0; // arc swept in this bin [m] (× slab depth: the area)
    double mass = 0, charge = 0;
    long toner = 0;
  };
  const std::vector<Bin> &profile() const { return profile_; }
  // The bin's centre measured from the exposed strip's centre [m] (exposed: |position| < duty·period/2);
  // on a uniform image from the block's start.
  double bin_position(int k) const;
  double block_length() const { return block_; } // [m]

  std::string periods_csv() const;
  std::string profile_csv() const;
  void write_state(StateOut &out) const;
  void read_state(StateIn &in);

private:
  // Count the elements of the swept sub-interval [from, to] (positions along the sweep from
  // s_previous_) and the toner among `candidates` that lies in it.
  void count_segment(double from, double to, bool last, const std::vector<LineToner> &candidates);
  void close_period(double time, double s_cut);
  void align_to_grid();
  // Where s lies in its block, in [0, 1): the image's phase on strips.
  double phase(double s) const;

  DrumImage image_;
  double depth_;
  int bins_;
  double block_;        // the image period, or the block length of a uniform image [m]
  double phase_offset_; // duty/2 on strips (a strip's centre at the block's duty/2), else 0
  // The sweep: the line's arc at the previous sample, its direction along s (+1 or −1, 0: not
  // known yet) and its time.
  bool has_previous_ = false, previous_counting_ = false;
  double s_previous_ = 0, t_previous_ = 0, direction_ = 0;
  std::vector<std::int32_t> counted_; // toner counted and still on the drum, sorted
  // The open period.
  Period open_;
  bool open_started_ = false;
  bool open_partial_ = false; // the open block began off the grid: swept, not kept
  double swept_ = 0;
  std::vector<Bin> open_bins_, profile_;
  std::vector<Period> periods_;
  // Work space, kept to avoid allocation per sample.
  std::vector<LineToner> candidates_;
  std::vector<std::int32_t> still_counted_;
};

} // namespace magbrush::dem
