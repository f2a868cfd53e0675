// The latent image on the drum, in the drum's own frame.
//
// The strips are those of the field stage (field_solver/nip_electrostatics.h latent_image_value):
// along the drum surface arc s, counted counter-clockwise about the drum centre from the nip
// point, exposed where frac(s/period + duty/2) < duty (an exposed strip centred on the nip at
// t = 0). A uniform image (electric.image.duty 1: a solid area; duty 0 or no period: dark) is
// the same everywhere. A point of the drum surface moves with s(t) = s₀ + ω_d R_d t, so the image is fixed in
// the drum's frame at s_drum = s − ω_d R_d t: that is the coordinate a printed page keeps.
#pragma once

#include "dem/measurements/nip_frame.h"

#include "case/case_model.h"

namespace magbrush::dem {

class DrumImage
{
public:
  DrumImage(const LatentImage &image, const NipFrame &frame);
  // The arc coordinate of a point in the drum's frame at time t [m].
  double drum_arc(double px, double py, double t) const;
  // The drum-frame arc of the drum surface point at nip coordinate x at time t [m].
  double drum_arc_at_x(double x, double t) const;
  bool exposed(double s_drum) const;
  // Exposed length of the drum-frame arc interval [a, b] [m] (a ≤ b).
  double exposed_length(double a, double b) const;
  // Where s lies in the image's period: frac(s/period + duty/2), in [0, 1); exposed below duty,
  // the exposed strip's centre at duty/2. 0 on a uniform image.
  double phase(double s_drum) const;
  double period() const { return period_; } // [m]; 0: uniform (no strips)
  double duty() const { return duty_; }
  bool solid() const { return solid_; }     // uniform and exposed everywhere

private:
  double period_, duty_;
  bool solid_;
  NipFrame frame_;
  double nip_angle_; // angle at the drum centre of the nip point (towards the sleeve) [rad]
};

} // namespace magbrush::dem
