/// @file   PhaseTransition.cc
/// @brief  Heating, boiling, evaporation and merging between a liquid and the fast gas solver
///         ([RYY15] Sec. 4, Eqs. 15, 18 - 20).
#include "ghostfx/gas/PhaseTransition.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/Timing.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <unordered_set>

namespace ghostfx {
namespace gas {

using sph::secondsSince;

namespace {

template <typename... Args>
std::string msg(Args&&... args)
{
    std::ostringstream s;
    (s << ... << args);
    return s.str();
}

/// Deterministic value in [0, 1) from a particle id (splitmix64 finaliser).
Real evaporationPhase(sph::ParticleId id)
{
    std::uint64_t z = std::uint64_t(id) + 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return Real(double(z >> 11) * (1.0 / 9007199254740992.0)) * Real(0.999);
}

bool isSolidKind(ParticleKind k)
{
    return k == ParticleKind::GhostSolid || k == ParticleKind::Boundary;
}

} // namespace

// Settings ----------------------------------------------------------------------------------------

// Set-up ------------------------------------------------------------------------------------------

PhaseTransition::PhaseTransition(GasSolver& gas, LiquidSide& liquid, const PhaseSettings& settings)
    : mGas(gas)
    , mLiquid(liquid)
    , mSettings(settings)
{
    mSettings.validate();
    mBoilPattern = mSettings.boilingPattern ? *mSettings.boilingPattern : icosahedronPattern();
    mEvapPattern =
        mSettings.evaporationPattern ? *mSettings.evaporationPattern : paperCubePattern();
    mMerge = mSettings.merge;
    if (!mMerge.resplitPattern) {
        mMerge.resplitPattern =
            optimisePattern("liquid re-split", patternOffsets(PatternShape::Icosahedron),
                            double(mSettings.liquidResplitEpsilon), std::cbrt(1.0 / 12.0));
    }
    mMerge.candidateKind = ParticleKind::Liquid;
    ensureChannels();
}

void PhaseTransition::ensureChannels()
{
    ParticleSet& p = mLiquid.particles();
    p.addScalarChannel(TEMPERATURE, mSettings.initialTemperature);
    addSplitChannels(p, mLiquid.supportRadius());
    p.addScalarChannel(LATENT, Real(0));
    p.addScalarChannel(EVAPORATION, Real(0));
}

void PhaseTransition::addHeater(const sph::LevelSet& shape, Real temperature)
{
    if (!(temperature > Real(0)) || !std::isfinite(temperature)) {
        throw ValueError(msg("heater '", shape.name(), "': temperature = ", temperature,
                             " K: expected a finite value > 0"));
    }
    if (!(mSettings.heaterBand < shape.bandWidth())) {
        throw ValueError(msg("heater '", shape.name(), "': heaterBand = ", mSettings.heaterBand,
                             " m reaches the level set's narrow band (", shape.bandWidth(),
                             " m), beyond which phi is clamped: widen the band or reduce "
                             "heaterBand"));
    }
    mHeaters.push_back(
        Heater{shape, temperature, shape.bounds().padded(Real(2) * shape.voxelSize())});
}

void PhaseTransition::setLiquidTemperature(Real temperature)
{
    if (!(temperature > Real(0)) || !std::isfinite(temperature)) {
        throw ValueError(
            msg("liquid temperature = ", temperature, " K: expected a finite value > 0"));
    }
    ParticleSet& p = mLiquid.particles();
    auto& T = p.scalarChannel(TEMPERATURE);
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid) T[i] = temperature;
    }
}

// Heat: heater relaxation and [RYY15] Eq. 15 among liquid particles ----------------------------------

void PhaseTransition::heat(Real dt)
{
    ParticleSet& p = mLiquid.particles();
    const std::size_t n = p.size();
    const Real R = mLiquid.supportRadius();
    const Real rho0 = mLiquid.restDensity();
    const sph::CubicSplineKernel kernel(R);
    searchHeatNeighbours();

    const auto& x = p.positions();
    const auto& m = p.masses();
    const auto& rho = p.densities();
    const auto& kind = p.kinds();
    const auto& T = p.scalarChannel(TEMPERATURE);
    const Real Dc = mSettings.conductivity;
    const Real gamma2 = mSettings.diffusionEpsilon * R * R;
    const Real band = mSettings.heaterBand;
    auto density = [&](std::size_t j) { return rho[j] > Real(0) ? rho[j] : rho0; };

    std::vector<Real> Tnew(n);
    mSurface.assign(n, 0);
    parallel::forEach(0, n, [&](std::size_t i) {
        Tnew[i] = T[i];
        if (kind[i] != ParticleKind::Liquid) return;
        const Real rhoI = density(i);
        double dTdt = 0;
        // Colour-field gradient sum_j V_j gradW_ij: about 0 inside, large at a surface.
        Vec3d colour(0.0);
        for (const Index j : mHeatLists[i]) {
            const Vec3 xij = x[i] - x[j];
            const Real r = xij.length();
            const ParticleKind kj = kind[j];
            const bool liquidJ = kj == ParticleKind::Liquid;
            if (!liquidJ && !isSolidKind(kj)) continue;
            const Real rhoJ = density(j);
            const Vec3 gradW = kernel.gradW(xij, r);
            colour += Vec3d(gradW * (m[j] / rhoJ));
            if (!liquidJ || j == i || Dc == Real(0)) continue;
            // Eq. 15: dT_i/dt = sum_j m_j / (rho_i rho_j) D_c (T_i - T_j) x_ij.gradW_ij /
            // (r^2 + gamma^2); x_ij.gradW_ij < 0, so heat flows from hot to cold.
            const Real xg = xij.dot(gradW);
            dTdt += double(m[j] / (rhoI * rhoJ) * Dc * (T[i] - T[j]) * xg / (r * r + gamma2));
        }
        for (const Heater& h : mHeaters) {
            // Beyond the level set's active box phi is the background, at least its band
            // width, which addHeater() checked is more than heaterBand: no lookup needed.
            if (!h.reach.contains(x[i])) continue;
            if (h.shape.phi(x[i]) < band)
                dTdt += double((h.temperature - T[i]) / mSettings.heatingTime);
        }
        Tnew[i] = Real(double(T[i]) + double(dt) * dTdt);
        mSurface[i] = colour.length() * double(R) > double(mSettings.surfaceThreshold);
    });
    storeHeat(Tnew);
}

void PhaseTransition::searchHeatNeighbours()
{
    // One vectorised search into lists (the liquid solver left its particles sorted by cell).
    ParticleSet& p = mLiquid.particles();
    const std::size_t n = p.size();
    const Real R = mLiquid.supportRadius();
    sph::NeighborGrid grid(R);
    grid.build(p.positions());
    mHeatQueries.resize(n);
    for (std::size_t i = 0; i < n; ++i) mHeatQueries[i] = p.kinds()[i] == ParticleKind::Liquid;
    mHeatLists.build(grid, p.positions().data(), n, R, mHeatQueries.data());
}

void PhaseTransition::storeHeat(std::vector<Real>& Tnew)
{
    // Heat beyond the boiling point goes into the latent store (L / c_p, K), T stays at T_b.
    ParticleSet& p = mLiquid.particles();
    const std::size_t n = p.size();
    const auto& kind = p.kinds();
    auto& T = p.scalarChannel(TEMPERATURE);
    auto& latent = p.scalarChannel(LATENT);
    const Real Tb = mSettings.boilingPoint;
    for (std::size_t i = 0; i < n; ++i) {
        if (kind[i] != ParticleKind::Liquid) continue;
        if (!std::isfinite(Tnew[i])) {
            throw NumericalError(msg("phase transition: liquid particle id ", p.ids()[i],
                                     " has a non-finite temperature after the heat step; reduce "
                                     "dt, conductivity or raise heatingTime"));
        }
        if (Tnew[i] > Tb) {
            latent[i] += Tnew[i] - Tb;
            Tnew[i] = Tb;
        }
        T[i] = Tnew[i];
    }
}

// Boiling and evaporation ([RYY15] Sec. 4.2) ----------------------------------------------------------

std::size_t PhaseTransition::transfer(Real dt)
{
    const std::vector<Index> boil = selectBoiling();
    const std::vector<sph::ParticleId> evaporate = selectEvaporation(dt, boil.size());
    if (boil.empty() && evaporate.empty()) return 0;
    splitLiquid(boil, evaporate);
    mBoiled += boil.size();
    mEvaporated += evaporate.size();
    handVapourToGas();
    return boil.size() + evaporate.size();
}

std::vector<Index> PhaseTransition::selectBoiling() const
{
    // A liquid particle boils when its latent store is full (at most maxTransitionsPerStep).
    const ParticleSet& p = mLiquid.particles();
    const auto& kind = p.kinds();
    const auto& T = p.scalarChannel(TEMPERATURE);
    const auto& latent = p.scalarChannel(LATENT);
    const std::size_t cap = mSettings.maxTransitionsPerStep;
    std::vector<Index> boil;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (kind[i] != ParticleKind::Liquid) continue;
        if (cap && boil.size() >= cap) break;
        if (T[i] >= mSettings.boilingPoint && latent[i] >= mSettings.latentHeat) {
            boil.push_back(Index(i));
        }
    }
    return boil;
}

std::vector<sph::ParticleId> PhaseTransition::selectEvaporation(Real dt, std::size_t boiling)
{
    // A surface particle above the onset accumulates evaporationRate f(T) dt pending splits;
    // one whole split is due when the pending count passes its staggered threshold.
    ParticleSet& p = mLiquid.particles();
    const auto& kind = p.kinds();
    const auto& T = p.scalarChannel(TEMPERATURE);
    const auto& latent = p.scalarChannel(LATENT);
    auto& pending = p.scalarChannel(EVAPORATION);
    const Real Tb = mSettings.boilingPoint, Ton = mSettings.evaporationOnset;
    const std::size_t cap = mSettings.maxTransitionsPerStep;
    std::vector<sph::ParticleId> ids;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (kind[i] != ParticleKind::Liquid || !mSurface[i] || !(T[i] > Ton)) continue;
        if (T[i] >= Tb && latent[i] >= mSettings.latentHeat) continue; // boils instead
        const Real f = std::min(Real(1), (T[i] - Ton) / (Tb - Ton));
        pending[i] += mSettings.evaporationRate * f * dt;
        // The threshold is staggered per particle by a hash of its id, so a surface that starts
        // with equal temperatures does not evaporate in lockstep (no quantisation of the rate).
        if (pending[i] + evaporationPhase(p.ids()[i]) >= Real(1)
            && (!cap || boiling + ids.size() < cap)) {
            pending[i] -= Real(1);
            ids.push_back(p.ids()[i]);
        }
    }
    return ids;
}

void PhaseTransition::splitLiquid(const std::vector<Index>& boil,
                                  const std::vector<sph::ParticleId>& evaporate)
{
    // Boiling: every daughter becomes gas. Evaporation: the centre stays liquid.
    ParticleSet& p = mLiquid.particles();
    SplitOptions boilOptions;
    boilOptions.outerKind = ParticleKind::Gas;
    boilOptions.centreKind = ParticleKind::Gas;
    if (!boil.empty()) splitParticles(p, boil, mBoilPattern, boilOptions);
    if (evaporate.empty()) return;
    // The boiling split moved the particles: find the evaporating ones again by id.
    const std::unordered_set<sph::ParticleId> wanted(evaporate.begin(), evaporate.end());
    std::vector<Index> evap;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid && wanted.count(p.ids()[i])) {
            evap.push_back(Index(i));
        }
    }
    SplitOptions evapOptions;
    evapOptions.outerKind = ParticleKind::Gas;
    evapOptions.centreKind = ParticleKind::Liquid;
    splitParticles(p, evap, mEvapPattern, evapOptions);
}

void PhaseTransition::handVapourToGas()
{
    // Hand every gas daughter to the gas solver with its exact mass. Its support radius is the
    // one a gas particle of that mass has at its birth density, the liquid's: h_rest(m)
    // (rho0_gas / rho0_liquid)^(1/3), so a newborn vapour particle has the neighbour count of
    // a gas at rest (Sec. 4.2's volume expansion then grows h back to h_rest(m) as the vapour
    // expands, GasSolver::expandSupports). Sized for the gas at rest instead, the daughters of
    // a boiling layer, packed at the liquid's density, had about 1,300 neighbours each.
    ParticleSet& p = mLiquid.particles();
    const double birth =
        std::cbrt(double(mGas.settings().restDensity) / double(mLiquid.restDensity()));
    const double hGas = double(mGas.settings().supportRadius());
    const double mGasRef = double(mGas.referenceParticleMass());
    const auto& T = p.scalarChannel(TEMPERATURE);
    std::vector<Vec3> xs, vs;
    std::vector<Real> Ts, ms, hs;
    std::vector<std::uint8_t> remove(p.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Gas) continue;
        remove[i] = 1;
        xs.push_back(p.positions()[i]);
        vs.push_back(p.velocities()[i]);
        Ts.push_back(T[i]);
        ms.push_back(p.masses()[i]);
        const double hRest = hGas * std::cbrt(double(p.masses()[i]) / mGasRef);
        hs.push_back(Real(hRest * std::min(1.0, birth)));
        mVapourMass += double(p.masses()[i]);
    }
    p.removeIf(remove);
    if (!xs.empty()) mGas.addGasParticles(xs, vs, Ts, ms, hs);
    mVapourCreated += xs.size();
}

void PhaseTransition::mergeLiquid()
{
    ParticleSet& p = mLiquid.particles();
    if (mMerge.sizeRule == MergeSizeRule::VolumeSum && mMerge.referenceMass == Real(0)) {
        // Re-split daughters get about the liquid's own support radius back: h' from the merged
        // mass at the liquid's reference mass and support radius.
        mMerge.sizeRule = MergeSizeRule::ReferenceDensity;
        mMerge.referenceMass = mLiquid.particleMass();
        mMerge.referenceRadius = mLiquid.supportRadius();
    }
    if (!(mMerge.referenceMass > Real(0))) return; // the liquid has no mass yet
    sph::NeighborGrid grid(mLiquid.supportRadius() * mMerge.neighbourhoodFactor);
    grid.build(p.positions());
    const MergeResult r = mergeParticles(p, grid, mMerge);
    mMerges += r.merges;
}

// The liquid as the gas's boundary ([RYY15] Sec. 3.3) ---------------------------------------------

void PhaseTransition::updateBoundary()
{
    const ParticleSet& p = mLiquid.particles();
    const Real cell = mGas.settings().spacing;
    struct Bin
    {
        std::int64_t key;
        Vec3d x;
        Vec3d v;
        int count;
    };
    std::vector<std::pair<std::int64_t, Index>> keyed;
    keyed.reserve(p.size());
    constexpr std::int64_t OFFSET = std::int64_t(1) << 20, BITS = 21;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        const Vec3& x = p.positions()[i];
        std::int64_t key = 0;
        for (int a = 0; a < 3; ++a) {
            const std::int64_t c = std::int64_t(std::floor(x[a] / cell)) + OFFSET;
            key = (key << BITS) | (std::clamp<std::int64_t>(c, 0, (std::int64_t(1) << BITS) - 1));
        }
        keyed.emplace_back(key, Index(i));
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<Vec3> xs, vs;
    for (std::size_t k = 0; k < keyed.size();) {
        std::size_t e = k;
        Vec3d x(0.0), v(0.0);
        while (e < keyed.size() && keyed[e].first == keyed[k].first) {
            x += Vec3d(p.positions()[keyed[e].second]);
            v += Vec3d(p.velocities()[keyed[e].second]);
            ++e;
        }
        const double c = double(e - k);
        xs.push_back(sph::toVec3(x / c));
        vs.push_back(sph::toVec3(v / c));
        k = e;
    }
    mBoundaryCount = xs.size();
    mGas.setExternalBoundary(xs, vs, mGas.referenceParticleMass());
}

// Checkpoints ----------------------------------------------------------------------------------------

namespace {
constexpr const char* PHASE_SOLVER = "phase_transition";
}

sph::SolverState PhaseTransition::saveState() const
{
    sph::SolverState state;
    state.solver = PHASE_SOLVER;
    state.integers["boiled"] = std::int64_t(mBoiled);
    state.integers["evaporated"] = std::int64_t(mEvaporated);
    state.integers["merges"] = std::int64_t(mMerges);
    state.integers["vapour_created"] = std::int64_t(mVapourCreated);
    state.integers["boundary_count"] = std::int64_t(mBoundaryCount);
    state.integers["step"] = std::int64_t(mStep);
    state.reals["vapour_mass"] = mVapourMass;
    state.reals["gas_removed"] = mGasRemoved;
    return state;
}

void PhaseTransition::restoreState(const sph::SolverState& state)
{
    if (state.solver != PHASE_SOLVER) {
        throw ValueError(msg("phase transition: the state was saved by '", state.solver,
                             "', expected '", PHASE_SOLVER, "'"));
    }
    mBoiled = std::size_t(state.count("boiled"));
    mEvaporated = std::size_t(state.count("evaporated"));
    mMerges = std::size_t(state.count("merges"));
    mVapourCreated = std::size_t(state.count("vapour_created"));
    mBoundaryCount = std::size_t(state.count("boundary_count"));
    mStep = std::uint64_t(state.count("step"));
    mVapourMass = state.real("vapour_mass");
    mGasRemoved = state.real("gas_removed");
}

// The coupled step ----------------------------------------------------------------------------------

double PhaseTransition::gasMass() const
{
    // The liquid's own mass in the gas: with entrainment a vapour particle also holds the air it
    // drew in, and its smoke share c is the vapour's part of its mass (GasEntrainment.h).
    const ParticleSet& g = mGas.particles();
    const std::vector<Real>* ambient =
        g.hasScalarChannel(channel::AMBIENT) ? &g.scalarChannel(channel::AMBIENT) : nullptr;
    const std::vector<Real>* share =
        g.hasScalarChannel(channel::SMOKE) ? &g.scalarChannel(channel::SMOKE) : nullptr;
    double sum = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
        if (g.kinds()[i] != ParticleKind::Gas) continue;
        if (ambient && (*ambient)[i] != Real(0)) continue;
        const double m = double(g.masses()[i]);
        sum += share ? m * double((*share)[i]) : m;
    }
    return sum;
}

MassBudget PhaseTransition::massBudget() const
{
    MassBudget b;
    const ParticleSet& p = mLiquid.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid) b.liquid += double(p.masses()[i]);
    }
    b.gas = gasMass();
    b.gasRemoved = mGasRemoved;
    return b;
}

void PhaseTransition::step(Real dt)
{
    if (!(dt > Real(0)) || !std::isfinite(dt)) {
        throw ValueError(
            msg("phase transition step: dt = ", dt, " s: expected a finite value > 0"));
    }
    const auto start = std::chrono::steady_clock::now();
    auto t0 = start;
    mLiquid.step(dt);
    mTimings.liquid += secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    ensureChannels(); // cheap if present; a liquid solver could have rebuilt its set
    heat(dt);
    mTimings.heat += secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    bool changed = transfer(dt) > 0;
    if (++mStep % std::uint64_t(mSettings.mergeEverySteps) == 0) {
        const std::size_t before = mMerges;
        mergeLiquid();
        changed = changed || mMerges > before;
    }
    if (changed) mLiquid.particlesChanged();
    mTimings.transition += secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    updateBoundary();
    mTimings.boundary += secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    mGas.step(dt);
    mGasRemoved += mGas.removedLastStep();
    mTimings.gas += secondsSince(t0);
    mTimings.total += secondsSince(start);
    ++mTimings.steps;
}

} // namespace gas
} // namespace ghostfx
