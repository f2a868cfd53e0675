// Wall-clock accounting of the step's phases (PhaseTimes), inside and outside the threads'
// parallel region. Internal to the engine.
#pragma once

#include <omp.h>

namespace magbrush::dem {

// Scoped wall-clock accumulation into one PhaseTimes slot (serial code).
class PhaseTimer
{
public:
  explicit PhaseTimer(double &slot) : slot_(slot), start_(omp_get_wtime()) {}
  ~PhaseTimer() { slot_ += omp_get_wtime() - start_; }

private:
  double &slot_;
  double start_;
};

// Inside a parallel region: the master thread charges the wall time since its last mark to a
// phase (the phases after the pair kernel have no barrier between them, so this is the
// master's own share, which equals the others' on balanced static loops).
class PhaseClock
{
public:
  PhaseClock() : master_(omp_get_thread_num() == 0), last_(master_ ? omp_get_wtime() : 0.0) {}
  void charge(double &slot)
  {
    if (!master_)
      return;
    const double now = omp_get_wtime();
    slot += now - last_;
    last_ = now;
  }

private:
  bool master_;
  double last_;
};

} // namespace magbrush::dem
