/// @file   GasSettings.h
/// @brief  Settings of the gas solver: fast SPH gas without ambient air [RYY15] and its baselines.
/// @details Plain struct with documented defaults. Each scene key's range, unit and meaning is
///          declared once, in gasSettingTable() (GasSettings.cc): the scene reader, `validate()` (a
///          one-line ValueError naming the field, the bad value and the range expected) and
///          docs/scene-format.md follow it. The solver copies its settings at construction. Where [RYY15] gives a value the default cites it; where the
///          paper is silent the comment says how the default was chosen.
///
///          Symbols (paper -> field): kappa (Eq. 11) -> `kappa`, rho0 -> `restDensity`, delta
///          (Sec. 3.1) -> `delta`, P_a (Eq. 13) -> `atmosphericPressure`, beta (Sec. 5) ->
///          `interiorPressureScale`, C_N (Sec. 3.2) -> `normalThreshold`, C_d (Eq. 14) ->
///          `damping`, D_c (Eq. 15) -> `diffusion`, D_r (Eq. 16) -> `radiationTime`, C_b (Eq. 17)
///          -> `buoyancy`, beta of Eq. 25 -> `vorticityGeneration`, l_s (Sec. 5) -> `lifeStrength`.
#pragma once

#include <ghostfx/sph/SettingSpec.h>
#include <ghostfx/sph/Types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace gas {

using sph::Real;
using sph::Vec3;

/// Which method advances the gas. Chosen by name in scenes ("fast", "ambient", "uncorrected").
enum class Method {
    /// [RYY15] Secs. 3 and 5: only the visible gas is simulated; density correction (Eq. 8),
    /// force compensation (Eq. 10), atmospheric pressure (Eq. 13), damping (Eq. 14), radiation
    /// at the gas boundary (Eq. 16).
    Fast,
    /// The standard approach of [RYY15] Fig. 1a / 4b: the domain box is filled with ambient air
    /// particles (gas particles marked by the "ambient" channel) inside walls of boundary
    /// particles; no correction or compensation.
    Ambient,
    /// The ablation of [RYY15] Fig. 4c: no ambient air and no correction or compensation
    /// (Eqs. 8, 10, 13, 14 off); buoyancy, diffusion and radiation as in Fast.
    Uncorrected,
};

/// "fast", "ambient" or "uncorrected".
const char* methodName(Method method);
/// Parse a method name; throws ValueError listing the valid names.
Method methodFromName(const std::string& name);

/// The turbulence model of the gas: what stands for the eddies below its spacing. Chosen by
/// name in scenes ("auto", "none", "entrainment").
enum class Turbulence {
    /// Entrainment for the methods without ambient air (fast, uncorrected, boiling vapour),
    /// none for the ambient baseline, which simulates its air (the default).
    Automatic,
    /// None: [RYY15] as published; a plume from a steady source rises as a column.
    None,
    /// Ambient air entrained through the gas boundary at `entrainment` times the gas's speed
    /// along it ([MTT56]; GasEntrainment.h): plumes widen and slow as measured plumes do.
    Entrainment,
};

/// "auto", "none" or "entrainment".
const char* turbulenceName(Turbulence turbulence);
/// Parse a turbulence model's name; throws ValueError listing the valid names.
Turbulence turbulenceFromName(const std::string& name);

/// How an attractor's pull falls off outside its core radius R (Attractor).
enum class Falloff {
    /// |a| = S (R / r)^2 for r >= R: the gravity of a uniform ball of radius R (the default).
    InverseSquare,
    /// |a| = S for r >= R: the same pull at any distance.
    Constant,
};

/// "inverse_square" or "constant".
const char* falloffName(Falloff falloff);
/// Parse a falloff name; throws ValueError listing the valid names.
Falloff falloffFromName(const std::string& name);

/// A point attractor: a body force pulling gas towards `position`, the "magic attractor" that
/// draws the plumes of [RYY15] Fig. 7. The paper shows the effect but gives no formula; this
/// one is the gravity of a uniform ball of radius R whose surface pull is S: with r = |c - x|,
///
///     a(x) = S (c - x) / R                       for r < R   (linear core: zero and finite at c)
///     a(x) = S (c - x) / r * (R / r)^2           for r >= R  (Falloff::InverseSquare)
///     a(x) = S (c - x) / r                       for r >= R  (Falloff::Constant)
///
/// continuous at r = R, where |a| = S is largest. A negative S repels. It acts on the visible
/// gas only (not on the ambient air of Method::Ambient: a conservative force on a uniform
/// fluid only builds up a pressure gradient, which would leave the air still and hide it).
struct Attractor
{
    Vec3 position{0};        ///< c (m)
    Real strength = Real(1); ///< S (m/s^2): the pull at r = R; < 0 repels
    Real radius = Real(0.1); ///< R (m): core radius, > 0
    Falloff falloff = Falloff::InverseSquare;

    /// a(x) (m/s^2) at position x (m).
    Vec3 acceleration(const Vec3& x) const;
};

struct GasSettings
{
    Method method = Method::Fast;

    // Discretisation ---------------------------------------------------------------------------
    /// Particle spacing s (m): the Poisson-disk radius is 0.92 s as for the liquid ([SB12] 4.6).
    Real spacing = Real(0.05);
    /// Kernel support radius / spacing. [RYY15] uses the kernels of Mueller et al. 2003 ([20])
    /// without giving the ratio; [20] uses about 1.7. 2 gives about 35 neighbours.
    Real supportFactor = Real(2);
    /// Particle mass (kg); 0 = automatic: rho0 divided by the kernel sum sum_j W_ij measured in
    /// the interior of a reference block sampled like the gas (so a block at rest starts at rho0).
    Real particleMass = Real(0);

    // Gas -----------------------------------------------------------------------------------------
    /// rho0 (kg/m^3). [RYY15] Sec. 6: the gas phase has 1/1000 of the liquid's rest density.
    Real restDensity = Real(1);
    /// kappa of Eq. 11, p = kappa (rho - rho0) (m^2/s^2 = Pa per kg/m^3); the sound speed is
    /// sqrt(kappa). Not given by [RYY15]; 1 keeps the default 2 substeps at 30 fps (Sec. 6) within
    /// the acoustic CFL limit at the default spacing.
    Real kappa = Real(1);
    /// Clamp Eq. 11 at p >= 0: a gas cannot pull (an ideal gas has no tension). [RYY15] is
    /// silent; unclamped, particles with rho < rho0 attract their neighbours, which gives any
    /// gas without ambient air an artificial surface tension (tests/gas measure both).
    bool clampNegativePressure = true;
    /// delta of Sec. 3.1: the virtual particle k sits delta h from its particle ([RYY15]:
    /// "delta in [0.4, 0.7] usually brings more plausible results").
    Real delta = Real(0.5);
    /// P_a of Eq. 13 (Pa): strength of the atmospheric pressure pushing boundary particles
    /// inwards. Not given by [RYY15]; 0.05 compresses a gas at rest by about 5 % with the
    /// default kappa and rho0 (interior pressure about P_a).
    Real atmosphericPressure = Real(0.05);
    /// beta of Sec. 5, in [0, 1]: Eq. 13 is scaled by beta for particles with |n_i| below the
    /// threshold (interior). 1 leaves Eq. 13 as it is; near 0 gives more visual variation.
    Real interiorPressureScale = Real(1);
    /// C_N of Sec. 3.2, made dimensionless: a particle is on the gas boundary when
    /// |n_i| h_i > C_N (|n_i| scales as 1/h). A flat free surface gives about 1.5, a full
    /// neighbourhood of a Poisson-disk sample about 0.1 - 0.3 (tests/gas measure it).
    Real normalThreshold = Real(0.5);
    /// C_d of Eq. 14 (1/s): a_damp = -C_d v on boundary particles, the drag of the air that is
    /// not simulated. Not given by [RYY15]. Without turbulence, 7 makes the shipped plume
    /// (examples/gas_plume) rise as the ambient-air baseline's does (top within 25 %, centroid
    /// within 20 %, python/tests): 1 rose 1.36x as high on average, 3 1.29x, 10 0.93x
    /// (docs/study.md, gas plume). Negative (the default): automatic, boundaryDamping().
    Real damping = Real(-1);
    /// Dynamic viscosity mu (Pa s) of the viscosity force F_v of Eq. 22 (Mueller et al. 2003
    /// Laplacian kernel). Not given by [RYY15]; small enough that dt mu / (rho0 h^2) < 0.1 at
    /// the defaults.
    Real viscosity = Real(0.01);
    /// Gravity g of Eq. 22 (m/s^2). Default zero: without ambient air nothing balances the gas's
    /// weight, which a real atmosphere cancels by hydrostatic buoyancy; the thermal part of
    /// buoyancy is Eq. 17. Set it for heavy gases.
    Vec3 gravity{0, 0, 0};

    // Temperature (Sec. 3.3) ----------------------------------------------------------------------
    /// Ambient temperature (K): buoyancy (Eq. 17) and radiation (Eq. 16) act on T - T_ambient.
    Real ambientTemperature = Real(293.15);
    /// D_c of Eq. 15 (kg/(m s)); D_c / (2 rho) is the thermal diffusivity. 0 turns it off.
    Real diffusion = Real(0.01);
    /// D_r of Eq. 16 (s): boundary particles relax to the ambient temperature with this time
    /// constant. 0 turns radiation off.
    Real radiationTime = Real(5);
    /// C_b of Eq. 17 (m/s^2 per K): a_b = C_b (T - T_ambient) b. Default g / T_ambient, the
    /// Boussinesq value for air.
    Real buoyancy = Real(0.0335);
    /// b of Eq. 17: buoyancy direction (normalised by validate's user; need not be unit here).
    Vec3 buoyancyDirection{0, 1, 0};

    // Artificial vorticity (Sec. 5, Eqs. 25 - 26) -------------------------------------------------
    bool vorticity = false;
    /// beta of Eq. 25 (m): generation of vorticity at the gas boundary, d omega/dt += beta n x g,
    /// with g the gravity, or 9.81 m/s^2 against the buoyancy direction when gravity is zero.
    Real vorticityGeneration = Real(0.002);
    /// Scale (1/s) turning the vortex velocity of Eq. 26, sum_j V_j (omega_j x r_ij) W_ij (m/s),
    /// into an acceleration. [RYY15] calls Eq. 26 a force without giving its units.
    Real vorticityStrength = Real(5);

    /// C_d in use: `damping`, or where it is automatic 7 /s, and 0 while air is entrained (the
    /// entrained air's momentum is then the air's drag; with both, a plume slowed as
    /// w ~ z^-1.07 against [MTT56]'s z^-1/3, tests/gas/test_gas_entrainment.cc).
    Real boundaryDamping() const
    {
        if (damping >= Real(0)) return damping;
        return entrainmentInUse() > Real(0) ? Real(0) : Real(7);
    }

    // Turbulence (GasEntrainment.h) -------------------------------------------------------------
    /// The model; Automatic: entrainment, except for the ambient baseline (turbulenceInUse()).
    Turbulence turbulence = Turbulence::Automatic;
    /// alpha, the entrainment coefficient of Morton, Taylor and Turner 1956 ([MTT56]): ambient
    /// air at rest joins the gas through its boundary at alpha times the gas's speed along it.
    /// 0.12 spreads a steady plume at db/dz 0.08-0.11 over 5 to 15 source diameters
    /// (tests/gas/test_gas_entrainment.cc; measured plumes 0.08-0.16).
    Real entrainment = Real(0.12);

    /// The turbulence model `turbulence` resolves to for `method`.
    Turbulence turbulenceInUse() const
    {
        if (turbulence != Turbulence::Automatic) return turbulence;
        return method == Method::Ambient ? Turbulence::None : Turbulence::Entrainment;
    }
    /// alpha in use: `entrainment` with the entrainment model, else 0.
    Real entrainmentInUse() const
    {
        return turbulenceInUse() == Turbulence::Entrainment ? entrainment : Real(0);
    }

    // Force fields ------------------------------------------------------------------------------
    /// Point attractors acting on the visible gas in the force stage, added to Eq. 24 (the
    /// magic attractor of [RYY15] Fig. 7; see Attractor for the formula). Empty by default.
    std::vector<Attractor> attractors;

    // Isolated particles (Sec. 5) -----------------------------------------------------------------
    /// l_s (s): a particle with no neighbour loses dt (1 + epsilon), epsilon in [0, 0.1), per
    /// step and is removed below 0; it gets the full value back when it finds a neighbour.
    /// 0 never removes isolated particles.
    Real lifeStrength = Real(0.5);

    // Domain --------------------------------------------------------------------------------------
    /// Ambient: the box filled with air, closed by walls of boundary particles (required).
    /// Fast / uncorrected: a kill box (gas leaving it is removed); empty = no limit.
    sph::Aabb domain;

    // Time stepping -------------------------------------------------------------------------------
    Real frameRate = Real(30);  ///< frames per second
    int substeps = 2;           ///< fixed steps per frame ([RYY15] Sec. 6: 2); 0 = CFL-adaptive
    Real cflNumber = Real(0.4); ///< dt <= cfl h / (c + |v|max) and sqrt(h / |a|max), if adaptive
    /// Blow-up bound (m/s): a faster particle stops the run with a NumericalError. 0 = automatic:
    /// a particle may move at most 10 spacings in one step, and not faster than 100 sound speeds.
    Real maxSpeed = Real(0);

    std::uint64_t seed = 0; ///< random seed of all sampling and of the life-strength epsilon

    /// Kernel support radius h (m): the paper's h, the default of the per-particle "h" channel.
    Real supportRadius() const { return supportFactor * spacing; }
    /// Speed of sound of Eq. 11, sqrt(kappa) (m/s).
    Real soundSpeed() const;
    /// Blow-up speed bound (m/s) for a step of length dt (s).
    Real speedLimit(Real dt) const;

    /// Throws ValueError for a field outside its declared range, a zero buoyancy direction, a bad
    /// attractor, or method ambient without a domain at least two kernel radii wide.
    void validate() const;
};

/// The settings of scene object `settings.gas` (a gas scene's `settings`) GasSettings holds.
const sph::SettingTable<GasSettings>& gasSettingTable();

} // namespace gas
} // namespace ghostfx
