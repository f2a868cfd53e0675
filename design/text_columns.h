// Aligned text tables with names like "|B| ≤ 20 mT over 172–192°": printf's widths count bytes,
// these count characters (UTF-8), so the columns line up on screen.
#pragma once

#include <string>

namespace magbrush {

// `text` padded with blanks, or cut, to `width` characters.
inline std::string padded(const std::string &text, size_t width)
{
  std::string out;
  size_t shown = 0;
  for (char ch : text)
  {
    const bool starts_character = (static_cast<unsigned char>(ch) & 0xC0) != 0x80;
    if (starts_character && shown == width)
      break;
    out += ch;
    shown += starts_character;
  }
  return out + std::string(width - shown, ' ');
}

} // namespace magbrush
