#!/usr/bin/python3
"""The paper's figures and tables from EFSI-Bench result CSVs, each beside the paper's own.

  /usr/bin/python3 plots/make_plots.py --csv results/.../weak.csv [--csv more.csv ...] \
      [--accuracy-dir DIR] [--paper results/paper/paper_tables.csv] [--out DIR]

Writes into --out (PNG and PDF for every figure):
  fig3_weak_efficiency   weak scaling T_1/T_M against ranks      (paper Fig. 3, from Table 2)
  fig4_comm_fraction     communication time / elapsed, in %     (paper Fig. 4: text bound only)
  fig5_strong_speedup    strong scaling T_ref/T_M, linear line   (paper Fig. 5, from Table 4)
  table2_weak.md         T_M and T_1/T_M, ours and the paper's   (paper Table 2)
  table4_strong.md       T_M and T_ref/T_M, ours and the paper's (paper Table 4)
and, with --accuracy-dir (the accuracy driver's --out):
  fig2_energy_budget     -dK/dt, I, -eps_s, -eps_f and their sum, FFT reference and ACM (paper Fig. 2)
  particle_trajectories  particle centroids, ACM beside the FFT reference
  fig1_particle_surfaces the particles' phi = 1/2 surfaces at three times, ACM beside the FFT
                         reference, from the HDF5 snapshots (paper Fig. 1; h5py, scikit-image)
  accuracy_comparison.md how far ACM's particles are from the reference's at the end: centroids,
                         phi and the solid's shape

Only rows with valid=1 are used; skipped rows are counted in the log and in the figures.
Repeated runs of one point give the median.  Needs Debian's matplotlib (/usr/bin/python3).
A bad option or input gives one line on stderr and exit status 2.
"""

import argparse
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import results_data as rd  # noqa: E402
import snapshots as sn  # noqa: E402
import trajectories as tj  # noqa: E402

DEFAULT_PAPER = os.path.join(os.path.dirname(HERE), "results", "paper", "paper_tables.csv")
PAPER_MACHINE = "RICC, Xeon 5570, 8 cores/node"

# One colour and marker per (method, eps) in the input and the paper, in sorted order, so a
# configuration looks the same in every figure of a run; sync filled, async open (as in the paper).
COLOURS = ("tab:red", "tab:purple", "tab:blue", "tab:green", "tab:orange", "tab:brown", "tab:cyan", "tab:olive")
MARKERS = ("o", "D", "^", "s", "v", "P", "X", "*")
STYLE_SLOTS = {}  # (method, eps) -> index, set by assign_styles
LINESTYLES = ("-", "--", ":", "-.")


class UsageError(Exception):
    pass


class OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        raise UsageError(message)


def assign_styles(*series_lists):
    keys = sorted({(s.config.method, s.config.eps) for group in series_lists for s in group})
    STYLE_SLOTS.clear()
    STYLE_SLOTS.update((k, i) for i, k in enumerate(keys))


def style(config, setup_index=0):
    slot = STYLE_SLOTS.get((config.method, config.eps), len(STYLE_SLOTS))
    if config.blocking:  # the blocked SOR series in colours of their own
        slot += len(STYLE_SLOTS) + 1
    colour, marker = COLOURS[slot % len(COLOURS)], MARKERS[slot % len(MARKERS)]
    face = colour if config.comm == "sync" else "white"
    return dict(color=colour, marker=marker, markerfacecolor=face, markeredgecolor=colour,
                linestyle=LINESTYLES[setup_index % len(LINESTYLES)], markersize=6, linewidth=1.3)


def setup_indices(all_series):
    setups = sorted({s.setup for s in all_series})
    return {s: i for i, s in enumerate(setups)}


def rank_axis(ax, ranks):
    ax.set_xscale("log", base=2)
    if ranks:
        lo, hi = min(ranks), max(ranks)
        ticks = [2 ** k for k in range(int(math.log2(lo)), int(math.log2(hi)) + 1)]
        if len(ticks) > 8:
            ticks = ticks[::2]
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"{t:,}" for t in ticks])
        ax.set_xlim(lo / 1.4, hi * 1.4)
    ax.grid(True, which="major", alpha=0.3)


def no_data(ax, text):
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=10, wrap=True)


def ours_title(all_series, loaded):
    hosts = sorted({s.setup.host for s in all_series})
    title = "This benchmark" + (f" ({', '.join(hosts)})" if hosts else "")
    if loaded.skipped:
        title += f"\n[skipped: {loaded.skipped_text()}]"
    return title


def save(fig, out, name, formats, written):
    for fmt in formats:
        path = os.path.join(out, f"{name}.{fmt}")
        fig.savefig(path, dpi=150, bbox_inches="tight")
        written.append(path)


def scaling_figure(plt, paper, ours, loaded, kind):
    """Two panels: the paper's series on the left, ours on the right."""
    fig, (axp, axo) = plt.subplots(1, 2, figsize=(12, 4.8), sharey=(kind != "comm"))
    fields = rd.varying_setup_fields(ours)
    idx = setup_indices(ours)
    panels = ((axp, paper, f"Paper ({PAPER_MACHINE})", []), (axo, ours, ours_title(ours, loaded), fields))
    for ax, group, title, lab_fields in panels:
        ranks = sorted({p.ranks for s in group for p in s.points})
        for s in group:
            x = [p.ranks for p in s.points]
            if kind == "weak":
                y = s.ratio()
            elif kind == "strong":
                y = s.ratio()
            else:
                y = [100 * p.comm_fraction for p in s.points]
            if kind == "comm" and ax is axp:
                continue
            ax.plot(x, y, label=rd.label(s, lab_fields), **style(s.config, idx.get(s.setup, 0)))
        if kind == "strong":
            for s in group[:1] if len({(s.points[0].ranks, s.points[-1].ranks) for s in group}) == 1 else group:
                r0 = s.points[0].ranks
                xs = [r0, s.points[-1].ranks]
                ax.plot(xs, [1, xs[1] / r0], color="black", linewidth=1, linestyle="-", marker="",
                        label="linear" if s is group[0] else None)
        rank_axis(ax, ranks)
        ax.set_xlabel("MPI ranks M (cores in the paper)")
        ax.set_title(title, fontsize=10)
        if not group and not (kind == "comm" and ax is axp):
            no_data(ax, f"no valid {'strong' if kind == 'strong' else 'weak'}-scaling rows in the input")
    if kind == "weak":
        axp.set_ylabel("weak-scaling efficiency $T_1/T_M$")
        # The panels share y: room for our highest efficiency as well as the paper's.
        top = max([y for s in ours for y in s.ratio()] + [1.2])
        axp.set_ylim(0, top * 1.08)
    elif kind == "strong":
        axp.set_ylabel("speedup $T_{M_0}/T_M$ (paper: $M_0$ = 1024)")
        axp.set_yscale("log", base=2)
    else:
        axp.set_ylabel("communication time / elapsed  [%]")
        axo.set_ylabel("communication time / elapsed  [%]")
        # The paper's one figure for Fig. 4, a statement about its ACM runs.
        axp.axhline(22, color=style(rd.Config("acm", "sync", ""))["color"], linestyle="--", linewidth=1.3,
                    label="ACM: at most 22 % up to 8,192 cores\n(paper's text; Fig. 4 values not tabulated)")
        axp.text(0.5, 0.35, "The paper gives Figure 4 as a plot only;\nits text bounds ACM at 22 %\n"
                 "and puts SOR 'much' higher.", transform=axp.transAxes, ha="center", fontsize=9)
        rank_axis(axp, [1, 8192])
        axp.set_ylim(0, 100)
        axo.set_ylim(0, max([100 * p.comm_fraction for s in ours for p in s.points] + [10]) * 1.15)
    for ax in (axp, axo):
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8, loc={"weak": "lower left", "strong": "upper left"}.get(kind, "upper left"))
    fig.tight_layout()
    return fig


# --- Markdown tables -----------------------------------------------------------------------------

def display_path(path):
    """Inside the repository: relative to its root; elsewhere: absolute."""
    repo = os.path.dirname(HERE)
    full = os.path.abspath(path)
    return os.path.relpath(full, repo) if full.startswith(repo + os.sep) else full


def fmt_time(x):
    return f"{x:.4g}"


def markdown_scaling_table(series_list, kind, fields):
    """Rows: ranks; columns: series; cells: 'T_M (ratio)' plus the runs behind a median."""
    ranks = sorted({p.ranks for s in series_list for p in s.points})
    ratio_name = "T_1/T_M" if kind == "weak" else "T_ref/T_M"
    head = ["ranks"] + [rd.label(s, fields) for s in series_list]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in ranks:
        cells = [f"{r:,}"]
        for s in series_list:
            ratios = dict(zip((p.ranks for p in s.points), s.ratio()))
            p = next((p for p in s.points if p.ranks == r), None)
            if p is None:
                cells.append("")
            else:
                runs = f", median of {p.runs}" if p.runs > 1 else ""
                cells.append(f"{fmt_time(p.elapsed_s)} s ({ratios[r]:.3f}{runs})")
        lines.append("| " + " | ".join(cells) + " |")
    return lines, ratio_name


def write_table(path, kind, paper, ours, loaded, sources, paper_path):
    number, what = ("2", "Weak scaling") if kind == "weak" else ("4", "Strong scaling")
    ref = "T_1/T_M (T_1: the same configuration's time on 1 rank, or its smallest rank count)" \
        if kind == "weak" else "T_ref/T_M (T_ref: the same configuration's time at its smallest rank count)"
    out = [f"# Table {number} analogue: {what.lower()}, elapsed time T_M and {ref.split(' ')[0]}", "",
           f"Cells: `T_M` in seconds (slowest rank, measured steps only) and in brackets {ref}.",
           "Only rows with valid=1; repeated runs of one point give the median.", ""]
    out.append(f"## This benchmark ({', '.join(display_path(s) for s in sources)})")
    out.append("")
    if ours:
        fields = rd.varying_setup_fields(ours)
        lines, _ = markdown_scaling_table(ours, kind, fields)
        out += lines
        out.append("")
        setups = sorted({s.setup for s in ours})
        out.append("Set-up: " + "; ".join(s.describe(["block", "steps", "threads", "host"]) for s in setups) + ".")
        iterating = [s for s in ours if any(p.iterations is not None for p in s.points)]
        if iterating:
            out += ["", "Pressure iterations per step (SOR sweeps, multigrid V-cycles; median), by ranks:"]
            for s in iterating:
                per = ", ".join(f"{p.iterations:g} ({p.ranks:,})" for p in s.points if p.iterations is not None)
                out.append(f"- {rd.label(s, fields)}: {per}")
    else:
        out.append(f"No valid {kind}-scaling rows in the input.")
    if loaded.skipped:
        out += ["", f"Skipped: {loaded.skipped_text()}."]
    out += ["", f"## Paper, Table {number} ({PAPER_MACHINE}; {display_path(paper_path)})", ""]
    lines, _ = markdown_scaling_table(paper, kind, [])
    out += lines
    out.append("")
    if kind == "weak":
        out.append("Paper: 64^3 cells per core; ACM 50 steps (dt 1.25e-5), SOR 10 steps (dt 6.25e-5) with "
                   "1,000 (eps 1e-3) or 2,200 (eps 1e-4) SOR sweeps and 200 Crank-Nicolson sweeps in all.")
    else:
        out.append("Paper: 2048 x 1024 x 1024 cells, 16,384 particles; ACM 50 steps, SOR 10 steps with 1,058 "
                   "(eps 1e-3) or 6,128 (eps 1e-4) SOR sweeps and 70 Crank-Nicolson sweeps in all; "
                   "T_ref = T_1024.")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


# --- accuracy run ----------------------------------------------------------------------------------

def budget_terms(cols):
    """-dK/dt (central differences in time), I, -eps_s, -eps_f and their sum."""
    t, k = cols["time"], cols["kinetic"]
    n = len(t)
    dkdt = []
    for i in range(n):
        a, b = max(i - 1, 0), min(i + 1, n - 1)
        dkdt.append((k[b] - k[a]) / (t[b] - t[a]) if t[b] > t[a] else math.nan)
    terms = {
        "$-dK/dt$": [-v for v in dkdt],
        "$I$ (input)": cols["input"],
        r"$-\varepsilon_s$ (solid)": [-v for v in cols["eps_solid"]],
        r"$-\varepsilon_f$ (fluid)": [-v for v in cols["eps_fluid"]],
    }
    terms["sum (eq. 14)"] = [sum(v) for v in zip(*terms.values())]
    return t, terms


def energy_figure(plt, acc_dir):
    fig, axes = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True)
    ymin, ymax = math.inf, -math.inf
    for ax, (method, title) in zip(axes, (("fft", "(a) SMAC, exact FFT-tridiagonal pressure (reference)"),
                                          ("acm", "(b) ACM (this benchmark's explicit method)"))):
        cols = rd.read_numeric_csv(os.path.join(acc_dir, f"series-{method}.csv"))
        t, terms = budget_terms(cols)
        for (name, values), ls in zip(terms.items(), ("-", "-", "--", ":", "-.")):
            ax.plot(t, values, linestyle=ls, linewidth=1.8 if name.startswith("sum") else 1.3,
                    color="black" if name.startswith("sum") else None, label=name)
            finite = [v for v in values if math.isfinite(v)]
            ymin, ymax = min([ymin] + finite), max([ymax] + finite)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel("energy rate")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, ncol=3, loc="best")
    for ax in axes:
        pad = 0.05 * (ymax - ymin or 1)
        ax.set_ylim(ymin - pad, ymax + pad)
    axes[-1].set_xlabel("time t")
    fig.suptitle("Kinetic-energy budget $-dK/dt + I - \\varepsilon_s - \\varepsilon_f = 0$ (paper Fig. 2)", fontsize=11)
    fig.tight_layout()
    return fig


def trajectory_figure(plt, acc_dir, box):
    """x-y and x-z paths, y against t, and how far each ACM particle is from its FFT twin."""
    tracks = {m: tj.track(os.path.join(acc_dir, f"centroids-{m}.csv"), box) for m in ("fft", "acm")}
    pairs = tj.pair_tracks(tracks["fft"], tracks["acm"], box)
    fig, ((axxy, axxz), (axyt, axdist)) = plt.subplots(2, 2, figsize=(12, 9))
    cmap = plt.get_cmap("tab20")
    for i, (ref, j) in enumerate(zip(tracks["fft"], pairs)):
        colour = cmap(i % 20)
        acm = tracks["acm"][j] if j is not None else None
        for ax, xs, ys in ((axxy, "x", "y"), (axxz, "x", "z"), (axyt, "time", "y")):
            ax.plot(ref[xs], ref[ys], color=colour, linestyle="--", linewidth=1.2)
            if acm:
                ax.plot(acm[xs], acm[ys], color=colour, linestyle="-", linewidth=1.2)
            if ax is not axyt:
                ax.plot(ref[xs][:1], ref[ys][:1], color=colour, marker="o", markersize=3)
        if acm:
            common = sorted(set(ref["time"]) & set(acm["time"]))
            at_ref = {t: k for k, t in enumerate(ref["time"])}
            at_acm = {t: k for k, t in enumerate(acm["time"])}
            dist = [math.dist([ref[c][at_ref[t]] for c in "xyz"], [acm[c][at_acm[t]] for c in "xyz"])
                    for t in common]
            keep = [(t, d) for t, d in zip(common, dist) if d > 0]
            if keep:
                axdist.plot(*zip(*keep), color=colour, linewidth=1.2)
    paired = {j for j in pairs if j is not None}
    for j, acm in enumerate(tracks["acm"]):
        if j not in paired:
            axxy.plot(acm["x"], acm["y"], color="gray", linewidth=1)
            axxz.plot(acm["x"], acm["z"], color="gray", linewidth=1)
    axxy.plot([], [], color="black", linestyle="-", label=f"ACM ({len(tracks['acm'])} tracks)")
    axxy.plot([], [], color="black", linestyle="--", label=f"FFT reference ({len(tracks['fft'])} tracks)")
    axxy.legend(fontsize=8, loc="best")
    axxy.set(xlabel="streamwise x (unwrapped across the periodic side)", ylabel="wall-normal y", ylim=(0, box[1]))
    axxy.set_title("Centroid paths, side view (circles: start)", fontsize=10)
    axxz.set(xlabel="streamwise x (unwrapped)", ylabel="spanwise z (unwrapped)")
    axxz.set_title("Centroid paths, top view", fontsize=10)
    axyt.set(xlabel="time t", ylabel="wall-normal y", ylim=(0, box[1]))
    axyt.set_title("Wall-normal position against time", fontsize=10)
    axdist.set(xlabel="time t", ylabel="|centroid ACM - centroid FFT|")
    if axdist.get_lines():
        axdist.set_yscale("log")
    axdist.set_title("Distance between each ACM particle and its FFT twin", fontsize=10)
    for ax in (axxy, axxz, axyt, axdist):
        ax.grid(True, alpha=0.3)
    fig.suptitle("Particle trajectories: ACM (solid) beside the FFT reference (dashed), one colour per particle",
                 fontsize=11)
    fig.tight_layout()
    return fig


def surface_times(acc_dir, wanted):
    """The snapshots nearest each wanted time that both methods have: {method: [Snapshot]}."""
    runs = {m: sn.series(acc_dir, m) for m in ("acm", "fft")}
    if not all(runs.values()):
        return None
    common = sorted(set(s.step for s in runs["acm"]) & set(s.step for s in runs["fft"]))
    if not common:
        return None
    at = {m: {s.step: s for s in runs[m]} for m in runs}
    picked = []
    for t in wanted:
        step = min(common, key=lambda k: abs(at["acm"][k].time - t))
        if step not in picked:
            picked.append(step)
    return {m: [at[m][k] for k in picked] for m in runs}


def shaded(triangles, rgb):
    """One colour per triangle, lit from the viewer's upper left, so that the shapes read."""
    import numpy as np
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    light = np.array([-0.5, -0.6, 0.8])
    light /= np.linalg.norm(light)
    brightness = 0.35 + 0.65 * np.abs(normals @ light)
    return np.clip(np.outer(brightness, rgb), 0, 1)


def surfaces_figure(plt, chosen):
    """Rows ACM and FFT, one column per time: the phi = 1/2 surfaces in the box."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    columns = len(chosen["acm"])
    fig = plt.figure(figsize=(4.2 * columns, 8.4))
    for row, (method, title) in enumerate((("acm", "ACM"), ("fft", "FFT reference"))):
        for col, snap in enumerate(chosen[method]):
            ax = fig.add_subplot(2, columns, row * columns + col + 1, projection="3d")
            surface = sn.solid_surface(snap)
            if surface is not None:
                verts, faces = surface
                # Drawn as (x, z, y): the wall-normal y upwards.
                triangles = verts[faces][:, :, [0, 2, 1]]
                mesh = Poly3DCollection(triangles, linewidths=0)
                mesh.set_facecolor(shaded(triangles, (0.84, 0.15, 0.16)))
                ax.add_collection3d(mesh)
            lx, ly, lz = snap.length
            ax.set(xlim=(0, lx), ylim=(0, lz), zlim=(0, ly))
            ax.set_box_aspect((lx, lz, ly))
            ax.set_xlabel("x", fontsize=8)
            ax.set_ylabel("z", fontsize=8)
            ax.set_zlabel("y", fontsize=8)
            ax.tick_params(labelsize=6)
            ax.view_init(elev=18, azim=-60)
            ax.set_title(f"{title}, t = {snap.time:.4g}", fontsize=10)
    cells = "x".join(str(n) for n in chosen["acm"][0].cells)
    fig.suptitle(f"Particles as the surfaces phi = 1/2 ({cells} cells)\nACM (top) beside the FFT reference "
                 "(bottom) (paper Fig. 1)", fontsize=11)
    fig.tight_layout()
    return fig


def shape_table(acm, fft):
    """Each reference particle at the last chosen snapshot beside the ACM particle nearest
    it (periodic in x and z): how far apart, and their volumes and semi-axes
    (snapshots.particle_shapes)."""
    ref, other = sn.particle_shapes(fft), sn.particle_shapes(acm)
    length = fft.length

    def distance(a, b):
        d = [abs(p - q) for p, q in zip(a["centroid"], b["centroid"])]
        for ax in (0, 2):
            d[ax] = min(d[ax], length[ax] - d[ax])
        return math.hypot(*d)

    lines = [f"## Particle shapes at t = {fft.time:.4g}", "",
             f"The regions of phi > 1/2: {len(ref)} in the reference, {len(other)} in ACM. Semi-axes: "
             "those of the uniform ellipsoid with the region's second moments, largest first.", "",
             "| particle | distance | volume (FFT) | volume ACM / FFT - 1 | semi-axes (FFT) | "
             "semi-axes ACM / FFT - 1 |", "|---|---|---|---|---|---|"]
    worst = 0.0
    for i, r in enumerate(ref):
        if not other:
            break
        a = min(other, key=lambda o: distance(r, o))
        rel = [x / y - 1 for x, y in zip(a["semi_axes"], r["semi_axes"])]
        worst = max([worst] + [abs(v) for v in rel])
        lines.append(f"| {i} | {distance(r, a):.3g} | {r['volume']:.4g} | {a['volume'] / r['volume'] - 1:+.3g} | "
                     + ", ".join(f"{v:.3g}" for v in r["semi_axes"]) + " | "
                     + ", ".join(f"{v:+.3g}" for v in rel) + " |")
    lines += ["", f"Largest relative difference of a semi-axis: {worst:.3g}.", ""]
    return lines


def comparison_table(path, acc_dir, box, chosen):
    """accuracy_comparison.md: the paired particles' centroid distances at the last common
    output, and phi and the solid's shape at each chosen snapshot."""
    tracks = {m: tj.track(os.path.join(acc_dir, f"centroids-{m}.csv"), box) for m in ("fft", "acm")}
    pairs = tj.pair_tracks(tracks["fft"], tracks["acm"], box)
    dx = box[0] / chosen["acm"][0].cells[0] if chosen else None
    lines = ["# ACM against the FFT reference", "",
             f"Source: `{display_path(acc_dir)}`; box {box[0]:g} x {box[1]:g} x {box[2]:g}.", ""]
    rows = []
    for i, (ref, j) in enumerate(zip(tracks["fft"], pairs)):
        if j is None:
            rows.append(f"| {i} | {ref['time'][-1]:.4g} | (no ACM particle starts here) | | |")
            continue
        acm = tracks["acm"][j]
        t = min(ref["time"][-1], acm["time"][-1])
        a, r = acm["time"].index(t) if t in acm["time"] else None, ref["time"].index(t) if t in ref["time"] else None
        if a is None or r is None:
            continue
        d = math.dist([ref[c][r] for c in "xyz"], [acm[c][a] for c in "xyz"])
        rows.append(f"| {i} | {t:.4g} | {d:.3g} | {d / dx:.3g} | {acm['y'][a] - ref['y'][r]:+.3g} |" if dx else
                    f"| {i} | {t:.4g} | {d:.3g} | | {acm['y'][a] - ref['y'][r]:+.3g} |")
    lines += ["## Centroids at the last common output", "",
              "| particle | t | distance | in cells | y (ACM - FFT) |", "|---|---|---|---|---|"] + rows + [""]
    if chosen:
        lines += ["## phi and the solid's shape", "",
                  "Mismatch: the volume solid (phi > 1/2) in one method and not in the other, against the "
                  "reference's solid volume.", "",
                  "| t | max abs phi diff | mean abs phi diff | solid volume | mismatch | mismatch / solid |",
                  "|---|---|---|---|---|---|"]
        for a, b in zip(chosen["acm"], chosen["fft"]):
            d = sn.state_differences(a, b)
            share = d["mismatch_volume"] / d["solid_volume"] if d["solid_volume"] > 0 else math.nan
            lines.append(f"| {b.time:.4g} | {d['max_phi_diff']:.3g} | {d['mean_phi_diff']:.3g} | "
                         f"{d['solid_volume']:.4g} | {d['mismatch_volume']:.3g} | {share:.3g} |")
        lines.append("")
        lines += shape_table(chosen["acm"][-1], chosen["fft"][-1])
    with open(path, "w") as f:
        f.write("\n".join(lines))


# --- command line ---------------------------------------------------------------------------------

def parse_box(text):
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        v = []
    if len(v) == 1:
        v *= 3
    if len(v) != 3 or not all(math.isfinite(x) and x > 0 for x in v):
        raise argparse.ArgumentTypeError(f"box '{text}' is not L or LX,LY,LZ with positive lengths")
    return tuple(v)


def parse_times(text):
    try:
        times = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a list of times separated by commas")
    if not times or any(not math.isfinite(t) or t < 0 for t in times):
        raise argparse.ArgumentTypeError(f"'{text}': times must be zero or positive")
    return times


def parse_formats(text):
    f = [x.strip() for x in text.split(",") if x.strip()]
    bad = [x for x in f if x not in ("png", "pdf", "svg")]
    if not f or bad:
        raise argparse.ArgumentTypeError(f"formats '{text}': choose from png, pdf, svg")
    return f


def main(argv=None):
    p = OneLineParser(prog="make_plots.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--csv", action="append", default=[], help="results CSV (repeatable)")
    p.add_argument("--paper", default=DEFAULT_PAPER, help="the paper's tables (default results/paper/paper_tables.csv)")
    p.add_argument("--accuracy-dir", help="the accuracy driver's --out directory (series-*.csv, centroids-*.csv)")
    p.add_argument("--box", type=parse_box,
                   help="box lengths for unwrapping trajectories (default: from fields-acm.h5, else 7.2)")
    p.add_argument("--surface-times", type=parse_times, default=[0.0, 5.0, 20.0],
                   help="times of fig1_particle_surfaces, the nearest snapshots (default 0,5,20)")
    p.add_argument("--out", default="plots/out", help="output directory (default plots/out)")
    p.add_argument("--formats", type=parse_formats, default=["png", "pdf"], help="default png,pdf")
    try:
        args = p.parse_args(argv)
        if not args.csv and not args.accuracy_dir:
            raise UsageError("give at least one --csv or --accuracy-dir")
        for path in args.csv + [args.paper]:
            if not os.path.isfile(path):
                raise UsageError(f"no file {path}")
        if args.accuracy_dir:
            for name in ("series-acm.csv", "series-fft.csv", "centroids-acm.csv", "centroids-fft.csv"):
                if not os.path.isfile(os.path.join(args.accuracy_dir, name)):
                    raise UsageError(f"no file {os.path.join(args.accuracy_dir, name)}")
        loaded = rd.read_rows(args.csv)
        paper_weak, paper_strong = rd.paper_series(args.paper, 2), rd.paper_series(args.paper, 4)
        box = args.box
        if args.accuracy_dir and box is None:
            fields = os.path.join(args.accuracy_dir, "fields-acm.h5")
            box = sn.box(fields) if os.path.isfile(fields) else (7.2, 7.2, 7.2)
    except (UsageError, rd.DataError, ValueError, OSError) as e:
        print(f"make_plots.py: error: {e}", file=sys.stderr)
        return 2

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(args.out, exist_ok=True)
    written = []
    if args.csv:
        weak, strong = rd.series(loaded, "weak"), rd.series(loaded, "strong")
        assign_styles(weak, strong, paper_weak, paper_strong)
        print(f"{len(loaded.rows)} valid rows from {len(args.csv)} file(s): {len(weak)} weak and "
              f"{len(strong)} strong series" + (f"; skipped {loaded.skipped_text()}" if loaded.skipped else ""))
        for name, kind, paper, ours in (("fig3_weak_efficiency", "weak", paper_weak, weak),
                                        ("fig4_comm_fraction", "comm", paper_weak, weak),
                                        ("fig5_strong_speedup", "strong", paper_strong, strong)):
            fig = scaling_figure(plt, paper, ours, loaded, kind)
            save(fig, args.out, name, args.formats, written)
            plt.close(fig)
        for name, kind, paper, ours in (("table2_weak.md", "weak", paper_weak, weak),
                                        ("table4_strong.md", "strong", paper_strong, strong)):
            path = os.path.join(args.out, name)
            write_table(path, kind, paper, ours, loaded, args.csv, args.paper)
            written.append(path)
    if args.accuracy_dir:
        fig = energy_figure(plt, args.accuracy_dir)
        save(fig, args.out, "fig2_energy_budget", args.formats, written)
        plt.close(fig)
        fig = trajectory_figure(plt, args.accuracy_dir, box)
        save(fig, args.out, "particle_trajectories", args.formats, written)
        plt.close(fig)
        chosen = surface_times(args.accuracy_dir, args.surface_times)
        if chosen:
            fig = surfaces_figure(plt, chosen)
            save(fig, args.out, "fig1_particle_surfaces", args.formats, written)
            plt.close(fig)
        else:
            print("no HDF5 snapshots of both methods in the accuracy directory: fig1_particle_surfaces not drawn")
        path = os.path.join(args.out, "accuracy_comparison.md")
        comparison_table(path, args.accuracy_dir, box, chosen)
        written.append(path)
    for path in written:
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
