#!/usr/bin/env python3
"""Halo volume against compute per rank: a model of one Ghost SPH simulation over many MPI ranks.

Predicts, for a block of liquid cut into parts (slabs along its longest axis, or recursive
coordinate bisection), the halo each part receives per step (the liquid within one support
radius R of its region, owned by other parts) and the parallel efficiency that halo leaves.
The geometry is exact for a uniform block: a part's halo is the volume within R of its box,
inside the block and outside the box (faces, quarter-cylinder edges and ball corners, clipped
where the block ends), times the particle density. Its check against halos counted in a real
simulation state is `bench_liquid --halo` (bench/history/diary-2026-11.md,
"One simulation over many ranks").

Usage:
  python3 bench/halo_model.py check            # the dam-break block of bench_liquid (98k)
  python3 bench/halo_model.py tank             # the 100M-particle tank at 16-1024 ranks
  python3 bench/halo_model.py tank --cost-us 1.63 --cores 16 --bandwidth-gbs 12.5

All lengths are in particle spacings h; the sampler packs 0.75 particles per h^3 and the support
radius is 3 h ([SB12]).
"""
import argparse
import math

DENSITY = 0.75  # particles per h^3 ([SB12] sampler, bench_sampler.cc)
SUPPORT = 3.0   # R / h


def quarter_disc(e1, e2, r, n=400):
    """Area of {0 <= u <= e1, 0 <= v <= e2, u^2 + v^2 < r^2} (midpoint rule)."""
    du = e1 / n
    return sum(min(e2, math.sqrt(max(r * r - ((k + 0.5) * du) ** 2, 0.0))) * du
               for k in range(n))


def ball_corner(e1, e2, e3, r, n=120):
    """Volume of {0 <= u <= e1, 0 <= v <= e2, 0 <= w <= e3, u^2 + v^2 + w^2 < r^2}."""
    du, dv = e1 / n, e2 / n
    total = 0.0
    for i in range(n):
        u = (i + 0.5) * du
        for j in range(n):
            v = (j + 0.5) * dv
            rest = r * r - u * u - v * v
            if rest > 0:
                total += min(e3, math.sqrt(rest)) * du * dv
    return total


def halo_volume(lo, hi, domain, r):
    """Volume within r of box [lo, hi], inside `domain` (lo, hi) and outside the box."""
    size = [hi[a] - lo[a] for a in range(3)]
    ext = [(min(r, lo[a] - domain[0][a]), min(r, domain[1][a] - hi[a])) for a in range(3)]
    vol = 0.0
    for a in range(3):                      # faces
        b, c = [x for x in range(3) if x != a]
        vol += (ext[a][0] + ext[a][1]) * size[b] * size[c]
    for a in range(3):                      # edges: two axes extended, one along the edge
        b, c = [x for x in range(3) if x != a]
        for eb in ext[b]:
            for ec in ext[c]:
                if eb > 0 and ec > 0:
                    vol += quarter_disc(eb, ec, r) * size[a]
    for e0 in ext[0]:                       # corners
        for e1 in ext[1]:
            for e2 in ext[2]:
                if e0 > 0 and e1 > 0 and e2 > 0:
                    vol += ball_corner(e0, e1, e2, r)
    return vol


def parts_of(domain, count, scheme):
    """Boxes of `count` parts of a uniform block, cut as DomainDecomposition cuts it."""
    longest = max(range(3), key=lambda a: domain[1][a] - domain[0][a])

    def split(lo, hi, n):
        if n == 1:
            return [(lo, hi)]
        axis = longest if scheme == "slabs" else max(range(3), key=lambda a: hi[a] - lo[a])
        lower = n // 2
        cut = lo[axis] + (hi[axis] - lo[axis]) * lower / n
        hi1, lo2 = list(hi), list(lo)
        hi1[axis] = cut
        lo2[axis] = cut
        return split(lo, hi1, lower) + split(lo2, hi, n - lower)

    return split(list(domain[0]), list(domain[1]), count)


def halo_ratio(domain, count, scheme, r=SUPPORT):
    """(halo / owned over all parts, worst part's halo / owned) for a uniform block."""
    boxes = parts_of(domain, count, scheme)
    owned = [math.prod(hi[a] - lo[a] for a in range(3)) for lo, hi in boxes]
    halo = [halo_volume(lo, hi, domain, r) for lo, hi in boxes]
    return sum(halo) / sum(owned), max(h / o for h, o in zip(halo, owned))


def check(_args):
    # bench_liquid's dam break at 98k: a 0.4 x 0.8 x 0.4 m block at h = 0.00697 m, i.e.
    # 57.4 x 114.8 x 57.4 spacings (its air layer, about 10 % more particles in a shell one
    # kernel radius thick, is left out of the model).
    h = (0.75 * 0.4 * 0.8 * 0.4 / 100000) ** (1 / 3)
    dims = [0.4 / h, 0.8 / h, 0.4 / h]
    domain = ([0.0, 0.0, 0.0], dims)
    print(f"block {dims[0]:.1f} x {dims[1]:.1f} x {dims[2]:.1f} h, "
          f"{DENSITY * math.prod(dims):.0f} particles, R = {SUPPORT} h")
    print("| scheme | parts | model halo / owned (all) | model worst part |")
    print("|---|---|---|---|")
    for scheme in ("slabs", "bisection"):
        for count in (2, 4, 8, 16, 32, 64, 128):
            mean, worst = halo_ratio(domain, count, scheme)
            print(f"| {scheme} | {count} | {mean:.3f} | {worst:.3f} |")


def tank(args):
    # A 100M-particle tank: 10 x 5 x 0.5 m of water at h = (0.75 * 25 / 1e8)^(1/3) = 5.7 mm.
    volume = 10 * 5 * 0.5
    n = 1e8
    h = (DENSITY * volume / n) ** (1 / 3)
    dims = [10 / h, 5 / h, 0.5 / h]
    domain = ([0.0, 0.0, 0.0], dims)
    cost = args.cost_us * 1e-6 / args.cores       # s per owned particle-step on one rank
    byte_time = args.halo_bytes / (args.bandwidth_gbs * 1e9)
    print(f"tank 10 x 5 x 0.5 m, h = {h * 1000:.2f} mm ({dims[0]:.0f} x {dims[1]:.0f} x "
          f"{dims[2]:.0f} h), {n:.0e} particles; one rank = {args.cores} cores at "
          f"{args.cost_us} us per particle-step per core; halo {args.halo_bytes} B per particle "
          f"and step over {args.bandwidth_gbs} GB/s, {args.latency_us} us per message, "
          f"{args.exchanges} exchanges per step; imbalance {args.imbalance}")
    print("| scheme | ranks | particles per rank | halo / owned (worst) | compute ms | "
          "halo ms | latency + reductions ms | efficiency |")
    print("|---|---|---|---|---|---|---|---|")
    for scheme in ("slabs", "bisection"):
        for ranks in [int(r) for r in args.ranks.split(",")]:
            _, worst = halo_ratio(domain, ranks, scheme)
            owned = n / ranks
            compute = cost * owned * args.imbalance * (1 + args.halo_overhead * worst)
            halo = byte_time * worst * owned
            # Messages per exchange: slabs talk to the parts within R on either side; a
            # bisection part to its face, edge and corner neighbours (up to 26).
            slab = dims[0] / ranks
            neighbours = 2 * math.ceil(SUPPORT / slab) if scheme == "slabs" else 26
            latency = args.exchanges * neighbours * args.latency_us * 1e-6
            reductions = 2 * math.log2(ranks) * args.latency_us * 1e-6
            step = compute + halo + latency + reductions
            efficiency = cost * owned / step
            print(f"| {scheme} | {ranks} | {owned:.3g} | {worst:.3f} | {compute * 1e3:.1f} | "
                  f"{halo * 1e3:.2f} | {(latency + reductions) * 1e3:.3f} | "
                  f"{100 * efficiency:.0f} % |")


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["check", "tank"])
    parser.add_argument("--ranks", default="16,128,1024", help="rank counts for 'tank'")
    parser.add_argument("--cost-us", type=float, default=1.63,
                        help="us per liquid-or-air particle-step on one core (bench_liquid)")
    parser.add_argument("--cores", type=int, default=16, help="cores per rank (TBB threads)")
    parser.add_argument("--halo-bytes", type=float, default=60,
                        help="bytes per halo particle per step, all exchanges")
    parser.add_argument("--bandwidth-gbs", type=float, default=12.5,
                        help="network bandwidth per rank, GB/s (100 Gb/s InfiniBand: 12.5)")
    parser.add_argument("--latency-us", type=float, default=2.0, help="per message, us")
    parser.add_argument("--exchanges", type=int, default=3,
                        help="halo exchanges per step (positions, density, v*)")
    parser.add_argument("--halo-overhead", type=float, default=0.03,
                        help="cost of a halo particle (sort, pack, unpack) per owned particle")
    parser.add_argument("--imbalance", type=float, default=1.05,
                        help="largest over mean owned count (rebalanced above 1.1)")
    args = parser.parse_args()
    {"check": check, "tank": tank}[args.what](args)


if __name__ == "__main__":
    main()
