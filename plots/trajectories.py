"""Particle trajectories from centroid files (columns step,time,region,volume,x,y,z).

The solver lists the connected solid regions of each output sorted by their first cell, so a
region's number is not the same particle from one output to the next.  Here each particle
is followed by matching every region to the nearest track of the previous output (minimum
image across the periodic x and z sides, greedy by distance), and its x and z are unwrapped
so that a particle leaving through x = Lx keeps going.  A region that matches no track (two
particles joined or parted) starts a new track.  Standard library only.
"""

import collections
import math

from results_data import read_numeric_csv


def _delta(a, b, length, periodic):
    d = b - a
    if periodic:
        d -= length * round(d / length)
    return d


def track(path, box, max_jump=None):
    """Tracks: list of dicts with lists 'time', 'x', 'y', 'z' (x and z unwrapped)."""
    cols = read_numeric_csv(path)
    by_step = collections.OrderedDict()
    for i, step in enumerate(cols["step"]):
        by_step.setdefault(step, []).append((cols["time"][i], cols["x"][i], cols["y"][i], cols["z"][i]))
    lx, ly, lz = box
    if max_jump is None:
        max_jump = 0.25 * min(box)
    tracks, active = [], []
    for step, regions in by_step.items():
        pairs = []
        for ti in active:
            t = tracks[ti]
            for ri, (_, x, y, z) in enumerate(regions):
                dx = _delta(t["x"][-1], x, lx, True)
                dy = y - t["y"][-1]
                dz = _delta(t["z"][-1], z, lz, True)
                pairs.append((math.sqrt(dx * dx + dy * dy + dz * dz), ti, ri, dx, dz))
        pairs.sort()
        used_t, used_r, next_active = set(), set(), []
        for dist, ti, ri, dx, dz in pairs:
            if dist > max_jump or ti in used_t or ri in used_r:
                continue
            used_t.add(ti)
            used_r.add(ri)
            t = tracks[ti]
            time, _, y, _ = regions[ri]
            t["time"].append(time)
            t["x"].append(t["x"][-1] + dx)
            t["y"].append(y)
            t["z"].append(t["z"][-1] + dz)
            next_active.append(ti)
        for ri, (time, x, y, z) in enumerate(regions):
            if ri not in used_r:
                tracks.append({"time": [time], "x": [x], "y": [y], "z": [z]})
                next_active.append(len(tracks) - 1)
        active = next_active
    return tracks


def pair_tracks(reference, other, box):
    """For each reference track, the index of the other track that starts nearest (or None)."""
    out = []
    for r in reference:
        best, best_d = None, math.inf
        for i, o in enumerate(other):
            if o["time"][0] != r["time"][0]:
                continue
            d = math.dist((r["x"][0], r["y"][0], r["z"][0]), (o["x"][0], o["y"][0], o["z"][0]))
            if d < best_d:
                best, best_d = i, d
        out.append(best if best_d < 0.25 * min(box) else None)
    return out
