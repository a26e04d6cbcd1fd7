"""ghostfx: Ghost SPH liquids and fast SPH gases on OpenVDB, for pipeline scripts.

    import ghostfx
    scene = ghostfx.load_scene("examples/dam_break/scene.json", {"settings.stiffness": 5000})
    sim = ghostfx.Simulation(scene)
    sim.run(frames=3, on_frame=lambda s: print(s.frame, s.positions().shape))

The same code as the `ghostfx` command line: scene errors raise ValueError with its message.
Particle arrays are float64 NumPy copies (the solver reorders its storage every step).
"""
import json as _json
import os as _os
import tempfile as _tempfile

from ._ghostfx import LevelSet, Scene, Simulation, sample, __version__
from ._ghostfx import load_scene as _load_scene_file

__all__ = ["LevelSet", "Scene", "Simulation", "load_scene", "sample", "__version__"]


def load_scene(scene, overrides=None, folder=None):
    """Read a scene: a path to a .json (or role-tagged .vdb) file, or a dict in the scene format.

    `overrides` is a dict of the dotted keys of the command line's -D, e.g.
    {"settings.stiffness": 5000}. A dict scene's relative file paths are taken from `folder`
    (default: the current directory). A bad scene raises ValueError with the command line's
    message; a file that cannot be read raises OSError."""
    if not isinstance(scene, dict):
        return _load_scene_file(_os.fspath(scene), overrides)
    folder = _os.getcwd() if folder is None else _os.fspath(folder)
    with _tempfile.NamedTemporaryFile("w", suffix=".json", prefix="scene_", dir=folder, delete=False) as f:
        _json.dump(scene, f)
    try:
        return _load_scene_file(f.name, overrides)
    finally:
        _os.unlink(f.name)
