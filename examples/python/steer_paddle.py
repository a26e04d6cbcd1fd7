#!/usr/bin/env python3
"""A dam break steered from Python: a paddle moves back and forth each frame while the column
collapses towards it; the surge front (the liquid's largest x) is plotted with matplotlib.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/steer_paddle.py

Writes the frames the scene asks for to out/python_paddle/ and the plot to
out/python_paddle/surge_front.png.
"""
import math
import os
import sys

import ghostfx

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    scene = ghostfx.load_scene(os.path.join(HERE, "paddle_tank.json"))
    sim = ghostfx.Simulation(scene)
    folder = os.path.join("out", "python_paddle")
    first, last = scene.frame_range
    amplitude, period = 0.04, 0.5  # paddle stroke (m) and period (s)
    times, fronts, paddle = [], [], []
    x_paddle = 0.66
    while sim.frame < last:
        # Velocity of a sinusoidal stroke over the coming frame: x(t) = x0 - A sin(2 pi t / T).
        t = sim.time + 0.5 / scene.frame_rate
        v = -amplitude * 2 * math.pi / period * math.cos(2 * math.pi * t / period)
        sim.set_solid_velocity("paddle", (v, 0.0, 0.0))
        sim.advance_frame()
        x_paddle += v / scene.frame_rate
        if sim.frame >= first:
            sim.write_frame(folder)
        x = sim.positions("liquid")
        times.append(sim.time)
        fronts.append(x[:, 0].max())
        paddle.append(x_paddle)
        print(f"frame {sim.frame}: t = {sim.time:.3f} s, front {fronts[-1]:.3f} m, paddle face "
              f"{x_paddle:.3f} m, {sim.counts}", flush=True)

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed (Debian: python3-matplotlib): no plot", file=sys.stderr)
        return
    fig, ax = plt.subplots(figsize=(6, 3.5), dpi=120)
    ax.plot(times, fronts, label="surge front (largest liquid x)")
    ax.plot(times, paddle, "--", label="paddle face")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x (m)")
    ax.set_title("Dam break against a moving paddle (Ghost SPH, h = 2 cm)")
    ax.legend(loc="lower right")
    fig.tight_layout()
    png = os.path.join(folder, "surge_front.png")
    fig.savefig(png)
    print(f"plot: {png}")


if __name__ == "__main__":
    main()
