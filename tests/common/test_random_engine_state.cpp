// A random engine written to a state stream and read back continues the same sequence, in the
// byte layout checkpoints have always had (a length-prefixed array of the engine's text form).
#include "common/random_engine_state.h"

#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <vector>

using namespace magbrush;

TEST(RandomEngineState, ARestoredEngineDrawsWhatTheOriginalWouldHaveDrawn)
{
  std::mt19937_64 original(12345);
  for (int i = 0; i < 1000; ++i)
    original();
  MemoryStateOut out;
  put_random_engine(out, original);
  std::mt19937_64 restored(1); // another state, overwritten by the read
  MemoryStateIn in(out.bytes(), "test state");
  get_random_engine(in, restored);
  EXPECT_EQ(in.remaining(), 0u);
  for (int i = 0; i < 1000; ++i)
    ASSERT_EQ(original(), restored()) << "draw " << i;
}

TEST(RandomEngineState, TheLayoutIsTheOlderCheckpointsOne)
{
  std::mt19937_64 engine(7);
  engine.discard(17);
  MemoryStateOut helper;
  put_random_engine(helper, engine);
  // What the inflow and the release wrote before this helper: put_array of the text's chars.
  std::ostringstream text;
  text << engine;
  const std::string s = text.str();
  MemoryStateOut before;
  before.put_array(std::vector<char>(s.begin(), s.end()));
  EXPECT_EQ(helper.bytes(), before.bytes());
}

TEST(RandomEngineState, AStateThatDoesNotReadBackIsRefusedByName)
{
  MemoryStateOut out;
  out.put_string("not an engine");
  MemoryStateIn in(out.bytes(), "checkpoint 'x.bin'");
  std::mt19937_64 engine;
  try
  {
    get_random_engine(in, engine);
    FAIL() << "a corrupt engine state was accepted";
  }
  catch (const std::runtime_error &e)
  {
    EXPECT_NE(std::string(e.what()).find("checkpoint 'x.bin'"), std::string::npos) << e.what();
  }
}
