// A random engine's state in a state stream (common/state_stream.h), so that a restart draws
// the very numbers the run would have drawn had it never stopped.
//
// The engine is written in the standard's own text form (operator<<, which for the Mersenne
// twister is the whole state and reads back exactly), as a length-prefixed byte array: the
// layout the inflow and the carried-toner release have always written, so older checkpoints
// read unchanged.
#pragma once

#include "common/state_stream.h"

#include <sstream>
#include <string>

namespace magbrush {

template <class Engine>
void put_random_engine(StateOut &out, const Engine &engine)
{
  std::ostringstream text;
  text << engine;
  out.put_string(text.str());
}

template <class Engine>
void get_random_engine(StateIn &in, Engine &engine)
{
  std::istringstream text(in.get_string());
  text >> engine;
  if (!text)
    in.fail("is corrupt (a random engine's state does not read back)");
}

} // namespace magbrush
