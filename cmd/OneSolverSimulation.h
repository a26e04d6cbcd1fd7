/// @file   OneSolverSimulation.h
/// @brief  A Simulation over a single solver: the answers that forward to it, written once for
///         the liquid (GhostSolver) and the gas (GasSolver) simulations.
#pragma once

#include "Simulation.h"
#include "SimulationParts.h"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace cmd {

/// A Simulation whose state is one solver of type `Solver`, which has frame(), time(),
/// stepCount(), settings() (with cflNumber, frameRate and substeps), stableTimeStep(),
/// setStepObserver() and saveState().
template <typename Solver>
class OneSolverSimulation : public Simulation
{
public:
    int frame() const override { return mSolver->frame(); }
    double time() const override { return mSolver->time(); }
    std::uint64_t stepCount() const override { return mSolver->stepCount(); }
    double fixedTimeStep() const override { return fixedStep(mSolver->settings()); }
    double stabilityLimit() const override
    {
        return double(mSolver->stableTimeStep()) / double(mSolver->settings().cflNumber);
    }
    double cflTimeStep() const override { return double(mSolver->stableTimeStep()); }

    void setStepObserver(std::function<void(double)> observer) override
    {
        mSolver->setStepObserver([observer](const Solver&, sph::Real dt) { observer(double(dt)); });
    }

    std::vector<sph::SolverState> saveStates() const override { return {mSolver->saveState()}; }

protected:
    explicit OneSolverSimulation(std::unique_ptr<Solver> solver) : mSolver(std::move(solver)) {}

    /// The first columns of a statistics row: the frame, the step count, the time (s) and the
    /// last step `dt` (s).
    std::vector<std::pair<std::string, double>> stepColumns(int frame, double dt) const
    {
        return {{"frame", frame},
                {"step", double(mSolver->stepCount())},
                {"time", mSolver->time()},
                {"dt", dt}};
    }

    std::unique_ptr<Solver> mSolver;
};

} // namespace cmd
} // namespace ghostfx
