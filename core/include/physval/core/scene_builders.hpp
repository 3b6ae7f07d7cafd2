// Scenes built in code: the benchmark's circle gas and other generated scenes that
// tests, benchmarks and tools share.
#pragma once

#include <cstdint>

#include "physval/core/scene.hpp"

namespace physval {

// The circle gas of issue 3's benchmarks: n circles of radius 0.05 m and mass 1 kg at
// 30% packing (by area) in a square box of four walls, elastic (e = 1), frictionless,
// no gravity, dt = 1/60 s. Circles start on a jittered lattice without overlaps, with
// velocities uniform in direction and in speed on [0, 2] m/s. Same seed, same scene.
Scene make_circle_gas(int n, std::uint64_t seed);

// The side of the gas's box for n circles, m.
double circle_gas_box_side(int n);

// A pile (issue 9): n circles of radius 0.1 m and mass 1 kg with restitution e and
// friction mu (mu_s = mu_k, walls alike) dropped under gravity (0, -9.8) into a closed
// box of inner width 0.25 m x cols (cols = max(4, round(sqrt n))), from a jittered
// lattice of spacing 0.25 m starting 0.15 m above the floor, with velocities uniform on
// [-0.5, 0.5] m/s per axis; dt = 1/60 s, duration 10 s. Same seed, same scene.
Scene make_circle_pile(int n, double restitution, double friction, std::uint64_t seed);

}  // namespace physval
