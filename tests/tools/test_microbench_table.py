#!/usr/bin/python3
"""harness/microbench/to_markdown.py: each kernel's fraction of the roofline, from the run's
best probes and the kernel's counted flops and bytes."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "harness", "microbench", "to_markdown.py")


def row(name, gflops, gbps, flops, nbytes, triad, compute, weno=None, weno_flops=0.0):
    r = {"name": name + "/manual_time", "run_name": name + "/manual_time", "run_type": "iteration",
         "min_us": 1.0, "cpu_min_us": 1.0, "median_us": 2.0, "GBps": gbps, "GFLOPs": gflops,
         "flops_per_cell": flops, "bytes_per_cell": nbytes, "triad_GBps": triad, "triad_us": 100.0,
         "compute_GFLOPs": compute, "roofline_fraction": 0.0, "roof_fraction": 0.0}
    if weno is not None:
        r.update({"weno_GFLOPs": weno, "weno_flops_per_cell": weno_flops})
    return r


class RoofFraction(unittest.TestCase):
    def table(self, rows):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "run.json")
            with open(path, "w") as f:
                json.dump({"context": {"mpi_ranks": 2, "omp_threads": 1, "date": "today"}, "benchmarks": rows}, f)
            res = subprocess.run([sys.executable, SCRIPT, path], capture_output=True, text=True)
        self.assertEqual(res.returncode, 0, res.stderr)
        lines = res.stdout.splitlines()
        cells = {l.split("|")[1].strip(): [c.strip() for c in l.split("|")[2:-1]] for l in lines if l.startswith("| BM_")}
        return lines[0], cells

    def test_lower_roof_from_the_best_probes(self):
        # Best probes of the run: triad 10 GB/s (from the second row), compute 50 GFLOP/s
        # (from the first).  A compute-bound kernel (10 flop/B: the bandwidth roof is 100)
        # at 25 GFLOP/s is at half of the compute roof; a memory-bound one (0.1 flop/B: roof
        # 1 GFLOP/s) at 0.5 GFLOP/s at half of its roof too, and at half of the triad.
        heading, cells = self.table([row("BM_Dense", 25.0, 2.5, 100, 10, 8.0, 50.0),
                                     row("BM_Stream", 0.5, 5.0, 1, 10, 10.0, 40.0),
                                     row("BM_Halo", 0.0, 2.0, 0, 84, 9.0, 45.0)])
        self.assertIn("STREAM triad 10.0 GB/s per rank", heading)
        self.assertIn("compute probe 50.0 GFLOP/s per rank", heading)
        self.assertEqual(cells["BM_Dense"][-2:], ["0.250", "0.500"])
        self.assertEqual(cells["BM_Stream"][-2:], ["0.500", "0.500"])
        # No counted flops: the triad is its only roof.
        self.assertEqual(cells["BM_Halo"][-2:], ["0.200", "0.200"])

    def test_weno_flops_at_the_weno_roof(self):
        # Best probes: triad 10 GB/s, multiply-add 50 GFLOP/s, WENO5 25 GFLOP/s (third row).
        # A kernel of 100 flops per cell, 50 of them WENO5, and 10 B: the compute roof time
        # is 50/50 + 50/25 = 3 ns per cell (bytes: 1 ns); at 20 GFLOP/s it takes 5 ns, so 0.6
        # of its roof, while the multiply-add peak alone would say 0.4.
        heading, cells = self.table([row("BM_Mixed", 20.0, 2.0, 100, 10, 10.0, 50.0, 20.0, 50.0),
                                     row("BM_Dense", 25.0, 2.5, 100, 10, 8.0, 40.0, 22.0, 0.0),
                                     row("BM_Weno", 12.5, 0.1, 100, 1, 9.0, 45.0, 25.0, 100.0)])
        self.assertIn("WENO5 probe 25.0 GFLOP/s per rank", heading)
        self.assertEqual(cells["BM_Mixed"][-1], "0.600")
        self.assertEqual(cells["BM_Dense"][-1], "0.500")  # no WENO5 flops: the peak alone
        self.assertEqual(cells["BM_Weno"][-1], "0.500")

    def test_older_runs_without_the_weno_probe(self):
        heading, cells = self.table([row("BM_Mixed", 20.0, 2.0, 100, 10, 10.0, 50.0)])
        self.assertNotIn("WENO5", heading)
        self.assertEqual(cells["BM_Mixed"][-1], "0.400")


if __name__ == "__main__":
    unittest.main()
