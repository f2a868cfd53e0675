// Robustness: thousands of randomly damaged versions of a valid case (bytes deleted,
// inserted, swapped; lines duplicated or dropped; random overrides) must each either load or
// throw CaseError — never crash, hang, or leak another exception type.
#include "case/case_parser.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

using namespace magbrush;

namespace {
std::string read_file(const std::string &path)
{
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string mutate(std::string text, std::mt19937 &rng)
{
  static const std::string alphabet = "abcdefghijklmnopqrstuvwxyz0123456789 :-[]{},.&*!|>'\"#%@`\t\n\xC2\xB5\xFF";
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int k = 0; k < edits && !text.empty(); ++k)
  {
    const size_t at = rng() % text.size();
    switch (rng() % 6)
    {
    case 0: text.erase(at, 1 + rng() % 8); break;
    case 1: text.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
    case 2: std::swap(text[at], text[rng() % text.size()]); break;
    case 3: text[at] = alphabet[rng() % alphabet.size()]; break;
    case 4: // duplicate a line
    {
      const size_t b = text.rfind('\n', at), e = text.find('\n', at);
      if (b != std::string::npos && e != std::string::npos)
        text.insert(e, text.substr(b, e - b));
      break;
    }
    default: // drop a line
    {
      const size_t b = text.rfind('\n', at), e = text.find('\n', at);
      if (b != std::string::npos && e != std::string::npos)
        text.erase(b, e - b);
      break;
    }
    }
  }
  return text;
}
} // namespace

TEST(CaseFuzz, DamagedCasesLoadOrFailCleanly)
{
  std::mt19937 rng(20261122);
  int valid = 0, invalid = 0;
  for (const char *file : {"/cases/kawamoto_nip.yaml", "/cases/kweon_full_roller.yaml",
                           "/cases/kawamoto_brush_compression.yaml", "/tests/case/valid/full_roller.yaml"})
  {
    const std::string text = read_file(std::string(MAGBRUSH_SOURCE_DIR) + file);
    ASSERT_FALSE(text.empty());
    for (int i = 0; i < 600; ++i)
    {
      const std::string damaged = mutate(text, rng);
      try
      {
        parse_case_text(damaged, "fuzz.yaml");
        ++valid;
      }
      catch (const CaseError &e)
      {
        ++invalid;
        EXPECT_NE(std::string(e.what()).find("fuzz.yaml"), std::string::npos) << e.what();
      }
      catch (const std::exception &e)
      {
        ADD_FAILURE() << "not a CaseError: " << e.what() << "\n--- input ---\n" << damaged;
      }
    }
  }
  EXPECT_GT(invalid, 500); // the damage is mostly caught
  std::printf("fuzz: %d damaged cases still valid, %d rejected with a CaseError\n", valid, invalid);
}

TEST(CaseFuzz, RandomOverridesLoadOrFailCleanly)
{
  std::mt19937 rng(7);
  const std::string text = read_file(std::string(MAGBRUSH_SOURCE_DIR) + "/cases/kawamoto_nip.yaml");
  const std::vector<std::string> keys{"drum.gap", "roller.poles.S1.angle", "roller.poles", "sleeve", "dem.gravity",
                                      "populations.carrier.count", "materials.carrier", "blades", "x.y.z",
                                      "roller.poles.[9].angle", "roller.poles.[0]", "electric.image.duty", "."};
  const std::vector<std::string> values{"0.3mm", "95deg", "[1, 2]", "{a: 1}", "", "-1", "~", "&a [*a]", "[", "1e999",
                                        "true", "\"quoted mm\"", "12300", "[0, 0, -9.81 m/s^2]"};
  for (int i = 0; i < 2000; ++i)
  {
    const std::vector<std::string> overrides{keys[rng() % keys.size()] + "=" + values[rng() % values.size()]};
    try
    {
      parse_case_text(text, "fuzz.yaml", overrides);
    }
    catch (const CaseError &)
    {
    }
    catch (const std::exception &e)
    {
      ADD_FAILURE() << "not a CaseError for --set " << overrides[0] << ": " << e.what();
    }
  }
}
