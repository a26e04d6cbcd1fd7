"""ghostfx: Ghost SPH liquids and fast SPH gases on OpenVDB, for pipeline scripts.

    import ghostfx
    scene = ghostfx.load_scene("examples/dam_break/scene.json", {"settings.stiffness": 5000})
    sim = ghostfx.Simulation(scene)
    sim.run(frames=3, on_frame=lambda s: print(s.frame, s.positions().shape))

The same code as the `ghostfx` command line: scene errors raise ValueError with its message.
Particle arrays are float64 NumPy copies (the solver reorders its storage every step).
"""
from ._ghostfx import LevelSet, Scene, Simulation, load_scene, sample, __version__

__all__ = ["LevelSet", "Scene", "Simulation", "load_scene", "sample", "__version__"]
