#pragma once
// `aloft bench`'s breeze (apps/aloft/cmd_bench.cpp), for the tests that set a generated mobile knocking:
// a horizontal push of 0.2 g on every component, its direction turning by the golden angle from one
// component to the next.

#include <cmath>

#include "aloft/model.hpp"
#include "aloft/simulation.hpp"

namespace aloft::test {

// Sets the push as sim's external loads (they stay until sim.loads().clear()).
inline void blow_bench_breeze(const Model& m, Simulation& sim) {
  for (int i = 1; i < m.count; ++i) {
    const double a = 2.399963 * i;  // rad, the golden angle: directions spread round the circle
    sim.loads().force[i] = 0.2 * 9.81 * m.mass[i] * Vec3(std::cos(a), 0, std::sin(a));
  }
}

}  // namespace aloft::test
