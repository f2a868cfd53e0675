// How the engine's idle OpenMP threads wait at a barrier: spin for about as long as waking a
// sleeping thread costs, then sleep.
//
// Why: a step has two hand-overs between threads (dem_advance.cpp). A thread that sleeps at
// one takes ~25 µs to wake up on a virtual machine (measured: an empty barrier 22 µs with
// OMP_WAIT_POLICY=PASSIVE, 0.5 µs spinning) — a tenth of a 2-thread step of 14k particles.
// Spinning forever is worse: when another job holds a core, the spinning thread takes the
// time slices of the thread it waits for (measured 1.2 ms instead of 25 µs per region with a
// 200 µs spin). Spinning for as long as a wake-up costs, then sleeping, never loses more
// than that wake-up per hand-over against the better of the two (the classic
// spin-then-block rule), loaded or idle.
//
// The OpenMP runtime (GCC's libgomp) reads its settings once, when it is loaded: the
// executables call choose_openmp_waiting() first thing in main() and, when it returns
// true, re-execute themselves so that the runtime sees the new environment.
#pragma once

#include <string>

namespace magbrush::dem {

// Unless the user set OMP_WAIT_POLICY or GOMP_SPINCOUNT: sets OMP_WAIT_POLICY=PASSIVE
// (no spinning at all when there are more threads than cores) and GOMP_SPINCOUNT to the
// number of spin rounds that take `spin_seconds` on this CPU (measured now). Returns true
// when it changed the environment.
bool choose_openmp_waiting(double spin_seconds = 20e-6);

// The cost of one round of libgomp's spin-wait (a relaxed load and a pause instruction) [s],
// the fastest of a few timings.
double spin_round_seconds();

// One line for the log: the policy in effect, e.g. "spin 20 µs (GOMP_SPINCOUNT=1000), then sleep".
std::string openmp_waiting_description();

} // namespace magbrush::dem
