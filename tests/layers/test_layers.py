#!/usr/bin/python3
"""The layers of kernels/ (docs/architecture.md, "Layers"): each layer sees only itself and
the layers below it.

- In the build's compile commands, every kernels source is compiled with the include
  directories of its own layer and of the layers below it, and of no other: a
  target_link_libraries that reached upwards would show here.
- Every `#include "..."` in a layer's sources and headers names a header of its own layer or
  of a layer below (headers included only by headers never reach a compile command).
- Each pressure method sees the pressure-method interface (spec) and not another method.

  test_layers.py --compile-commands build/compile_commands.json --kernels kernels
"""
import argparse
import json
import os
import re
import sys
import unittest

# Each layer and the layers directly below it; "pressure/*" stands for every method folder.
BELOW = {
    "paper": [],
    "grid": ["paper"],
    "ops": ["grid"],
    "physics": ["ops"],
    "time": ["physics"],
    "pressure/spec": ["time"],
    "pressure/*": ["pressure/spec"],
    "pressure/registry": ["pressure/*"],
    "particles": ["grid"],
    "io": ["grid"],
    "cases": ["pressure/registry", "particles", "io"],
}
ARGS = None


def layers(kernels):
    """Every layer folder under kernels/, method folders by name."""
    out = []
    for d in sorted(os.listdir(kernels)):
        if not os.path.isdir(os.path.join(kernels, d)):
            continue
        if d == "pressure":
            for m in sorted(os.listdir(os.path.join(kernels, d))):
                if os.path.isdir(os.path.join(kernels, d, m)):
                    out.append("pressure/" + m)
        else:
            out.append(d)
    return out


def rule(layer):
    if layer in BELOW:
        return layer
    if layer.startswith("pressure/"):
        return "pressure/*"
    return None


def visible(layer, all_layers):
    """The layer itself and everything below it, as folder names."""
    seen, todo = set(), [layer]
    while todo:
        l = todo.pop()
        if l in seen:
            continue
        seen.add(l)
        for b in BELOW[rule(l)]:
            todo += [m for m in all_layers if rule(m) == "pressure/*"] if b == "pressure/*" else [b]
    return seen


class Layers(unittest.TestCase):
    def setUp(self):
        self.kernels = os.path.abspath(ARGS.kernels)
        self.layers = layers(self.kernels)

    def test_every_layer_has_a_rule_and_a_target(self):
        for l in self.layers:
            self.assertIsNotNone(rule(l), f"kernels/{l} is not in BELOW: say which layers it may use")
            with open(os.path.join(self.kernels, l, "CMakeLists.txt")) as f:
                text = f.read()
            self.assertRegex(text, r"efsi_layer\(|efsi_pressure_method\(", f"kernels/{l} makes no library target")

    def test_compile_commands_see_only_lower_layers(self):
        with open(ARGS.compile_commands) as f:
            commands = json.load(f)
        checked = 0
        for e in commands:
            path = os.path.abspath(e["file"])
            if not path.startswith(self.kernels + os.sep):
                continue
            layer = os.path.dirname(os.path.relpath(path, self.kernels))
            dirs = {os.path.relpath(os.path.abspath(i), self.kernels)
                    for i in re.findall(r"-I(\S+)", e["command"])
                    if os.path.abspath(i).startswith(self.kernels + os.sep)}
            with self.subTest(source=os.path.relpath(path, self.kernels)):
                self.assertEqual(dirs, visible(layer, self.layers))
            checked += 1
        self.assertGreater(checked, 20, "too few kernels sources in the compile commands")

    def test_includes_name_headers_of_lower_layers(self):
        where = {}
        for l in self.layers:
            for name in os.listdir(os.path.join(self.kernels, l)):
                if name.endswith(".hpp"):
                    self.assertNotIn(name, where, f"{name} in kernels/{l} and kernels/{where.get(name)}")
                    where[name] = l
        for l in self.layers:
            allowed = visible(l, self.layers)
            for name in sorted(os.listdir(os.path.join(self.kernels, l))):
                if not name.endswith((".hpp", ".cpp")):
                    continue
                with open(os.path.join(self.kernels, l, name)) as f:
                    for header in re.findall(r'^#include "([^"]+)"', f.read(), re.M):
                        if header not in where:
                            continue  # generated (registered_methods.inc)
                        with self.subTest(file=f"{l}/{name}", header=header):
                            self.assertIn(where[header], allowed,
                                          f"kernels/{l}/{name} includes {header} of kernels/{where[header]}, "
                                          "a layer it may not use")


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--compile-commands", required=True)
    ap.add_argument("--kernels", required=True)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
