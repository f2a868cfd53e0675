// Whether a case's nip field is zero everywhere: no bias and no latent image (none, or both of
// its values 0). The nip field is the bias solution plus the image's, so then there is nothing
// for the field stage to solve (magbrush-field stores no electric grid) and nothing for qE to
// act with (dem/force_terms/electric_field_force.cpp): both stages ask this one rule.
#pragma once

#include "case/case_model.h"

namespace magbrush {

inline bool electric_field_is_zero(const Case &c)
{
  const LatentImage &image = c.electric.image;
  const bool no_image = image.kind == LatentImage::Kind::none || (image.dark_value == 0.0 && image.light_value == 0.0);
  return c.electric.bias == 0.0 && no_image;
}

} // namespace magbrush
