"""ghostfx: Ghost SPH liquids and fast SPH gases on OpenVDB, for pipeline scripts.

    import ghostfx
    scene = ghostfx.load_scene("examples/dam_break/scene.json", {"settings.stiffness": 5000})
    sim = ghostfx.Simulation(scene)
    sim.run(frames=3, on_frame=lambda s: print(s.frame, s.positions().shape))

The same code as the `ghostfx` command line: scene errors raise ValueError with its message.
Particle arrays are float64 NumPy copies (the solver reorders its storage every step).
The files a run writes read back as NumPy arrays: read_points (points .vdb), read_volume
(volume grids), read_stats (stats.h5), read_checkpoint (checkpoint .h5).
"""
import csv as _csv
import json as _json
import os as _os
import shutil as _shutil
import subprocess as _subprocess
import tempfile as _tempfile

from ._ghostfx import LevelSet, Scene, Simulation, sample, __version__
from ._ghostfx import load_scene as _load_scene_file
from ._ghostfx import sample_cache_counts, set_sample_cache
from ._ghostfx import Volume, read_checkpoint, read_points, read_stats, read_volume

__all__ = ["Interrupted", "LevelSet", "Scene", "Simulation", "Volume", "load_scene",
           "read_checkpoint", "read_points", "read_stats", "read_volume", "sample",
           "sample_cache_counts", "set_sample_cache", "study", "__version__"]


class Interrupted(SystemExit):
    """Raised by Simulation.run() at the end of a frame after SIGTERM or SIGUSR1, the signals a
    render farm sends before it pre-empts a job. A SystemExit: left uncaught, the script exits
    with code 128 + the signal (143 for SIGTERM, 138 for SIGUSR1), as `ghostfx run` does.

    signal: the signal's number; frame: the last frame simulated; checkpoint: the checkpoint
    run(checkpoint=...) wrote for it, or None."""

    def __init__(self, signal, frame, checkpoint=None):
        super().__init__(128 + int(signal))
        self.signal = int(signal)
        self.frame = int(frame)
        self.checkpoint = checkpoint


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


def _program(executable=None):
    """The ghostfx program: given, $GHOSTFX_EXE, beside this package in a build tree
    (build/cmd/ghostfx) or an install prefix (bin/ghostfx), or on the PATH."""
    here = _os.path.dirname(_os.path.abspath(__file__))
    candidates = [executable, _os.environ.get("GHOSTFX_EXE"),
                  _os.path.join(here, "..", "..", "cmd", "ghostfx"),
                  _os.path.join(here, "..", "..", "..", "..", "bin", "ghostfx"),
                  _shutil.which("ghostfx")]
    for c in candidates:
        if c and _os.path.isfile(c) and _os.access(c, _os.X_OK):
            return _os.path.normpath(c)
    raise OSError("ghostfx.study: the ghostfx program was not found (give executable=, set "
                  "GHOSTFX_EXE, or put it on the PATH)")


def study(path, out=None, threads=0, executable=None):
    """Run a study (docs/study.md): every case of its sweep, the table and the plot, as
    `ghostfx study` does (its cases run as child ghostfx processes). Returns the table as a dict
    of column name -> list of values (numbers where the column holds numbers).

    A bad study file raises ValueError with the command line's message."""
    args = [_program(executable), "study", _os.fspath(path), "-q", "--threads", str(int(threads))]
    if out is not None:
        args += ["--out", _os.fspath(out)]
    run = _subprocess.run(args, capture_output=True, text=True)
    if run.returncode != 0:
        line = run.stderr.strip().splitlines()[-1] if run.stderr.strip() else f"exit code {run.returncode}"
        raise ValueError(line.removeprefix("ghostfx: error: "))
    with open(path) as f:
        text = f.read()
    try:
        spec = _json.loads(text)
    except ValueError:  # the scene format allows // comments
        import re
        spec = _json.loads(re.sub(r"(^|\s)//[^\n]*", r"\1", text))
    output = spec.get("output", {})
    folder = _os.fspath(out) if out is not None else output.get("directory", "out")
    table = _os.path.join(folder, output.get("table", "study.csv"))
    with open(table, newline="") as f:
        rows = list(_csv.DictReader(f))
    columns = {}
    for name in (rows[0].keys() if rows else []):
        values = [r[name] for r in rows]
        try:
            columns[name] = [float(v) for v in values]
        except ValueError:
            columns[name] = values
    return columns
