// The forward simulation's accuracy: energy balance on every shipped cycle, and self-convergence against a
// tight-tolerance reference run.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "rollsim/sim/simulation.hpp"

using namespace rollsim;

namespace {

VehicleModel model_of(const std::string& vehicle_file) {
  return VehicleModel::assemble(load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/" + vehicle_file));
}

}  // namespace

// Invariant: traction = rolling + aero + friction + regen + kinetic change, to 1e-4 of the traction, on every
// shipped cycle with both cars (artemis_motorway_150 included, which the electric car cannot follow: it falls
// behind at its top speed). Each interval's quadrature tolerance is a fraction of that interval's energy scale;
// a fixed 10 J per interval left WLTC, UDDS and Artemis urban at 1.3-4.7e-4.
TEST(EnergyBalance, ClosesToOneIn1e4OnEveryShippedCycleForBothCars) {
  for (const char* vehicle : {"ev.yaml", "ice.yaml"}) {
    const auto m = model_of(vehicle);
    for (const auto& cycle : shipped_cycle_names()) {
      const auto r = simulate_forward(m, load_cycle(cycle));
      SCOPED_TRACE(std::string(vehicle) + " " + cycle);
      EXPECT_LT(std::abs(r.energy.wheel_residual_j()) / r.energy.traction_j, 1e-4);
      EXPECT_LT(std::abs(r.energy.powertrain_residual_j()) / r.source_energy_j(), 1e-9);
    }
  }
}

// Self-convergence (as SUNDIALS' examples check against a reference solution): energies at the working
// tolerances against a run 1000 times tighter in every tolerance. The working run must agree to 2e-4 of the
// headline energy in each term (the spread measured is up to ~3e-5), and a 10 times looser run must be farther
// from the reference than the working run is: the error falls as the tolerance does.
TEST(EnergyBalance, WorkingToleranceConvergesToATightReference) {
  SimulationOptions tight;
  tight.relative_tolerance = 1e-8;
  tight.quadrature_energy_fraction = 1e-7;
  SimulationOptions loose;
  loose.relative_tolerance = 1e-4;
  loose.quadrature_energy_fraction = 1e-3;
  for (const char* vehicle : {"ev.yaml", "ice.yaml"}) {
    const auto m = model_of(vehicle);
    for (const char* cycle : {"nedc", "wltc"}) {
      const auto c = load_cycle(cycle);
      const auto ref = simulate_forward(m, c, tight);
      const auto work = simulate_forward(m, c);
      const auto coarse = simulate_forward(m, c, loose);
      SCOPED_TRACE(std::string(vehicle) + " " + cycle);
      const double scale_j = ref.source_energy_j();
      auto terms = [](const SimulationResult& r) {
        const auto& e = r.energy;
        return std::vector<double>{e.traction_j, e.rolling_j, e.aero_j, e.friction_brake_j, e.regen_wheel_j,
                                   e.gearbox_loss_j, e.motor_loss_j, e.battery_terminal_j, e.fuel_j, e.engine_loss_j};
      };
      const auto tr = terms(ref), tw = terms(work), tc = terms(coarse);
      double work_err = 0.0, coarse_err = 0.0;
      for (std::size_t k = 0; k < tr.size(); ++k) {
        EXPECT_LT(std::abs(tw[k] - tr[k]) / scale_j, 2e-4) << "term " << k;
        work_err = std::max(work_err, std::abs(tw[k] - tr[k]) / scale_j);
        coarse_err = std::max(coarse_err, std::abs(tc[k] - tr[k]) / scale_j);
      }
      EXPECT_LT(work_err, coarse_err);
      EXPECT_NEAR(work.distance_m / ref.distance_m, 1.0, 1e-5);
      EXPECT_LT(std::abs(ref.energy.wheel_residual_j()) / ref.energy.traction_j, 1e-6);
    }
  }
}
