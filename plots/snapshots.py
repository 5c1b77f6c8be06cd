"""Reading the drivers' HDF5 state files with h5py: snapshots (PREFIX-STEP.h5), the accuracy
driver's final fields (fields-METHOD.h5) and checkpoints.  Each field is a dataset of its
global points, z slowest and x fastest, with the file's step, time, cells and lengths as
attributes (docs/architecture.md, "Checkpoints and snapshots").

Also the phi = 1/2 surfaces of the particles (marching cubes from scikit-image) and the
differences between two states of the same box.  Needs Debian's python3-h5py and
python3-skimage (for /usr/bin/python3).
"""

import glob
import os
import re

# Where each field's points sit: the axes it lies on faces of (x, y, z).
FACES = {"u": "x", "v": "y", "w": "z", "p": "", "phi": "", "Bt11": "", "Bt22": "", "Bt33": "",
         "Bt12": "xy", "Bt13": "xz", "Bt23": "yz"}


class Snapshot:
    """One state file: .step, .time, .cells (nx, ny, nz), .length (Lx, Ly, Lz), and
    field(name) as a numpy array indexed [z, y, x]."""

    def __init__(self, path):
        import h5py
        self.path = path
        with h5py.File(path, "r") as f:
            attrs = dict(f.attrs)
            self.names = sorted(k for k in f.keys() if k in FACES)
        self.step = int(attrs["step"])
        self.time = float(attrs["time"])
        if "cells_x" in attrs:
            self.cells = tuple(int(attrs["cells_" + a]) for a in "xyz")
            self.length = tuple(float(attrs["length_" + a]) for a in "xyz")
        else:  # a checkpoint: its configuration entries
            self.cells = tuple(int(v) for v in attrs["config cells"].decode().split(","))
            self.length = tuple(float(v) for v in attrs["config length"].decode().split(","))

    def field(self, name):
        import h5py
        with h5py.File(self.path, "r") as f:
            return f[name][...]

    def spacing(self):
        return tuple(l / n for l, n in zip(self.length, self.cells))


def box(path):
    """(Lx, Ly, Lz) of a state file."""
    return Snapshot(path).length


# The folder of an accuracy directory that holds its phi-only snapshots (write_phi_only).
PHI_DIR = "phi"


def series(directory, method):
    """The snapshots of `method` in an accuracy --out directory (full ones first, then the
    phi-only ones of its phi/ folder), and its final fields file, sorted by step (one per
    step)."""
    found = {}
    for folder in (directory, os.path.join(directory, PHI_DIR)):
        for path in sorted(glob.glob(os.path.join(folder, f"snapshot-{method}-*.h5"))):
            if re.search(r"-\d{8}\.h5$", path):
                s = Snapshot(path)
                found.setdefault(s.step, s)
    final = os.path.join(directory, f"fields-{method}.h5")
    if os.path.isfile(final):
        s = Snapshot(final)
        found.setdefault(s.step, s)
    return [found[k] for k in sorted(found)]


def closest(snapshots, t):
    return min(snapshots, key=lambda s: abs(s.time - t))


def solid_surface(snapshot):
    """The phi = 1/2 surface: (vertices as x, y, z, faces), with phi's cell-centred points at
    (i + 1/2) dx.  None when phi never crosses 1/2."""
    from skimage import measure
    phi = snapshot.field("phi")
    if not (phi.min() < 0.5 < phi.max()):
        return None
    dx, dy, dz = snapshot.spacing()
    verts, faces, _, _ = measure.marching_cubes(phi, 0.5, spacing=(dz, dy, dx))
    # [z, y, x] -> x, y, z, shifted to the cell centres.
    xyz = verts[:, ::-1] + [0.5 * dx, 0.5 * dy, 0.5 * dz]
    return xyz, faces


def state_differences(a, b):
    """How two states of one box differ: max |phi_a - phi_b|, and the volume where one is
    solid (phi > 1/2) and the other is not, against the solid volume of `b`."""
    import numpy as np
    if a.cells != b.cells or a.length != b.length:
        raise ValueError(f"{a.path} and {b.path} are not the same box")
    pa, pb = a.field("phi"), b.field("phi")
    cell = float(np.prod(a.spacing()))
    solid_a, solid_b = pa > 0.5, pb > 0.5
    solid = solid_b.sum() * cell
    return {
        "max_phi_diff": float(np.abs(pa - pb).max()),
        "mean_phi_diff": float(np.abs(pa - pb).mean()),
        "solid_volume": float(solid),
        "mismatch_volume": float((solid_a != solid_b).sum() * cell),
    }


def particle_shapes(snapshot):
    """The particles of a state as the connected regions of phi > 1/2, joined across the
    periodic x and z sides (faces shared, as the drivers' centroids count them): for each, a
    dict of its volume, centroid (x, y, z) in the box, and semi-axes (largest first): those
    of the uniform ellipsoid with the region's second moments, sqrt(5 lambda) for each
    eigenvalue lambda, so that an ellipsoid's own semi-axes come back, and a biconcave disc
    shows as two long axes and one short.  Needs scipy (python3-scipy)."""
    import numpy as np
    from scipy import ndimage
    solid = snapshot.field("phi") > 0.5
    labels, count = ndimage.label(solid)
    # Union-find over the labels that meet across a periodic side ([z, y, x]: axes 2 and 0).
    parent = list(range(count + 1))

    def root(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for axis in (2, 0):
        lo, hi = np.take(labels, 0, axis=axis), np.take(labels, -1, axis=axis)
        for a, b in zip(lo[(lo > 0) & (hi > 0)], hi[(lo > 0) & (hi > 0)]):
            ra, rb = root(int(a)), root(int(b))
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    lengths = np.array(snapshot.length)  # x, y, z
    h = np.array(snapshot.spacing())
    cell = float(np.prod(h))
    members = {}
    for label in range(1, count + 1):
        members.setdefault(root(label), []).append(label)
    shapes = []
    for group in members.values():
        z, y, x = np.nonzero(np.isin(labels, group))
        pts = (np.stack([x, y, z], axis=1) + 0.5) * h
        # Unwrapped about its circular mean along each periodic axis (right for any region
        # shorter than the box there), then put back in the box.
        for a in (0, 2):
            angle = np.angle(np.exp(2j * np.pi * pts[:, a] / lengths[a]).mean())
            mid = lengths[a] * angle / (2 * np.pi)
            pts[:, a] = mid + (pts[:, a] - mid + lengths[a] / 2) % lengths[a] - lengths[a] / 2
        centre = pts.mean(axis=0)
        moments = np.cov((pts - centre).T, bias=True)
        semi = np.sqrt(5.0 * np.clip(np.linalg.eigvalsh(moments), 0.0, None))[::-1]
        centre[[0, 2]] %= lengths[[0, 2]]
        shapes.append({"volume": len(pts) * cell, "centroid": tuple(float(v) for v in centre),
                       "semi_axes": tuple(float(v) for v in semi)})
    return sorted(shapes, key=lambda s: s["centroid"])


def write_phi_only(source, target, single=False, zero_below=0.0):
    """Writes `target`: `source`'s phi (gzip with byte shuffle) and all its attributes but
    the other fields' staggerings, under a temporary name renamed when complete.  What the
    plots and the comparison read of a state is phi alone: the 128^3 case's full state is
    185 MB a file, its phi alone 15 MB once the interface has spread tails over the box
    (below 1e-6 in 64 % of the cells at t = 5).  By default phi is kept bit for bit;
    `single` rounds it to float32 and `zero_below` sets |phi| < zero_below to 0 (3 MB for
    1e-6 in that case), both recorded in the attribute `phi_reduced`.  Raises OSError naming the file when it cannot be read or
    written."""
    import h5py
    import numpy as np
    if os.path.abspath(source) == os.path.abspath(target):
        raise OSError(f"{target}: would overwrite its own source")
    with h5py.File(source, "r") as f:
        if "phi" not in f:
            raise OSError(f"{source}: no phi dataset")
        phi = f["phi"][...]
        attrs = dict(f.attrs)
    reduced = []
    if single:
        phi = phi.astype(np.float32)
        reduced.append("rounded to float32")
    if zero_below > 0.0:
        phi[np.abs(phi) < zero_below] = 0.0
        reduced.append(f"|phi| < {zero_below:g} set to 0")
    tmp = target + ".tmp"
    try:
        with h5py.File(tmp, "w") as g:
            nz, ny, nx = phi.shape
            g.create_dataset("phi", data=phi, compression="gzip", compression_opts=6, shuffle=True,
                             chunks=(min(nz, 16), ny, nx))
            for k, v in attrs.items():
                if not k.startswith("stagger_") or k == "stagger_phi":
                    g.attrs[k] = v
            if reduced:
                g.attrs["phi_reduced"] = ", ".join(reduced)
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
