// The message a case text is refused with, or "" when it parses: what the validation tests of
// a key read back (file, line, key and reason are all in it).
#pragma once

#include "case/case_parser.h"

#include <string>

namespace magbrush::testing {

inline std::string case_error_of(const std::string &yaml, const std::string &file_name)
{
  try
  {
    parse_case_text(yaml, file_name);
  }
  catch (const CaseError &e)
  {
    return e.what();
  }
  return "";
}

} // namespace magbrush::testing
