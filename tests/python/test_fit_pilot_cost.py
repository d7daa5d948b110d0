"""tools/fit_pilot_cost.py: its non-negative least squares, and a tiny timed run end to end.

Run by ctest with DWIVEDI_SOURCE_DIR and DWIVEDI_BUILD_DIR set (the tool runs the build's
dwivedi_bake_counts). The end-to-end run bakes a few 8 x 8 images: its times are noise, so it
checks the counts and the output's form, never a fitted value.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
import unittest


def environment(name):
    value = os.environ.get(name)
    if not value:
        raise AssertionError("%s is not set: run this test through ctest" % name)
    return value


def tool_module():
    sys.path.insert(0, os.path.join(environment("DWIVEDI_SOURCE_DIR"), "tools"))
    import fit_pilot_cost
    return fit_pilot_cost


class Fit(unittest.TestCase):
    def test_recovers_known_costs(self):
        fit = tool_module()
        # samples, walks, events, guided events, rays, queries, terms
        truth = [4000.0, 550.0, 650.0, 350.0, 750.0, 6500.0, 45.0]
        counts = [[1000, 500, 5000, 0, 3000, 0, 45000], [1000, 500, 3500, 3500, 2800, 0, 31000],
                  [1000, 1500, 6000, 6000, 5900, 0, 110000], [1000, 100, 900, 900, 500, 950, 8000],
                  [1000, 300, 800, 0, 760, 0, 7000], [1000, 1000, 5100, 5100, 7000, 0, 52000],
                  [1000, 3000, 10000, 10000, 4000, 0, 190000], [1000, 1000, 9000, 0, 4000, 0, 20000]]
        rows = [([float(c) for c in x], sum(t * c for t, c in zip(truth, x))) for x in counts]
        coef, rms = fit.fit(rows)
        self.assertLess(rms, 1e-9)
        for got, want in zip(coef, truth):
            self.assertAlmostEqual(got, want, delta=1e-6 * want)

    def test_costs_stay_non_negative(self):
        # Costs that fall with the ray count: the unconstrained fit's ray cost is negative.
        fit = tool_module()
        counts = [[100, 50, 500, 0, 100, 0, 900], [100, 50, 500, 0, 900, 0, 900], [100, 150, 900, 900, 300, 0, 2000],
                  [100, 50, 300, 300, 600, 10, 700], [100, 100, 700, 0, 200, 0, 1500],
                  [100, 300, 600, 600, 800, 0, 1000], [100, 200, 400, 0, 500, 0, 300]]
        rows = [([float(c) for c in x], 1000.0 + 5.0 * x[1] + 10.0 * x[2] - 2.0 * x[4] + 30.0 * x[5] + x[6])
                for x in counts]
        coef, rms = fit.fit(rows)
        self.assertEqual(len(coef), 7)
        self.assertTrue(all(c >= 0.0 for c in coef), coef)
        self.assertGreater(rms, 0.0)

    def test_names_are_the_pilots_constants(self):
        # The printed #define lines must replace pilot.c's, name for name, but for the constants
        # the tool names as held (fitted otherwise), which it must not also fit.
        fit = tool_module()
        with open(os.path.join(environment("DWIVEDI_SOURCE_DIR"), "src", "bake", "pilot.c")) as f:
            defined = set(re.findall(r"#define PILOT_COST_(\w+) ", f.read()))
        self.assertEqual(defined, set(fit.NAMES) | set(fit.HELD))
        self.assertFalse(set(fit.NAMES) & set(fit.HELD))


class EndToEnd(unittest.TestCase):
    def test_timed_run(self):
        source, build = environment("DWIVEDI_SOURCE_DIR"), environment("DWIVEDI_BUILD_DIR")
        with tempfile.TemporaryDirectory() as work:
            out = os.path.join(work, "fit.json")
            run = subprocess.run([sys.executable, os.path.join(source, "tools", "fit_pilot_cost.py"), "--build", build,
                                  "--measure", "time", "--repeats", "1", "--size", "8", "--spp", "2",
                                  "--scenes", "slab,default", "--techniques", "classical,backward,closest",
                                  "--json", out], capture_output=True, text=True, timeout=120)
            self.assertEqual(run.returncode, 0, run.stderr)
            for name in ("SAMPLE", "EVENT", "GUIDED_EVENT", "RAY", "QUERY", "TERM"):
                self.assertRegex(run.stdout, r"#define PILOT_COST_%s [0-9.e+]+\n" % name)
            with open(out) as f:
                data = json.load(f)
        rows = data["rows"]
        self.assertEqual(sorted((r["scene"], r["technique"]) for r in rows),
                         sorted((s, t) for s in ("slab", "default") for t in ("classical", "backward", "closest")))
        for r in rows:
            what = "%s %s" % (r["scene"], r["technique"])
            self.assertEqual(r["samples"], 8 * 8 * 2, what)
            self.assertGreater(r["events"], 0, what)
            self.assertGreater(r["rays"], 0, what)
            self.assertGreater(r["mixture_terms"], 0, what)
            self.assertGreater(r["cost"], 0.0, what)
            self.assertEqual(r["guided_events"], 0 if r["technique"] == "classical" else r["events"], what)
            self.assertEqual(r["point_queries"] > 0, r["technique"] == "closest", what)


class BadInput(unittest.TestCase):
    """Bad arguments end with a message and a non-zero exit, and the counting program prints
    nothing on stdout then (the tool parses its stdout as JSON)."""

    def test_counting_program(self):
        counts = os.path.join(environment("DWIVEDI_BUILD_DIR"), "dwivedi_bake_counts")
        good = ["default", "classical", "8", "8", "2", "1", "1"]
        # (exit code, argument index, value): WIDTH is argument 2, REPEATS 6, TECHNIQUE 1, SCENE 0
        cases = [(2, 2, "-1"), (2, 2, "4294967296"), (2, 2, "8x"), (2, 2, ""), (2, 6, "1001"), (2, 1, "nosuch"),
                 (1, 2, "0"), (1, 0, "/no/such/scene.json")]
        for code, index, value in cases:
            argv = list(good)
            argv[index] = value
            run = subprocess.run([counts] + argv, capture_output=True, text=True, timeout=60)
            self.assertEqual(run.returncode, code, (argv, run.stderr))
            self.assertEqual(run.stdout, "", argv)
            self.assertIn("dwivedi_bake_counts: ", run.stderr, argv)
        run = subprocess.run([counts] + good[:-1] + ["3"], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 0, run.stderr)
        self.assertEqual(len(json.loads(run.stdout)["seconds"]), 3)

    def test_fit_tool(self):
        source, build = environment("DWIVEDI_SOURCE_DIR"), environment("DWIVEDI_BUILD_DIR")
        tool = [sys.executable, os.path.join(source, "tools", "fit_pilot_cost.py"), "--build", build,
                "--measure", "time", "--scenes", "default", "--techniques", "classical"]
        for extra, message in ((["--spp", "0"], "--spp must be at least 1"),
                               (["--repeats", "0"], "--repeats must be at least 1"),
                               (["--seed", "-1"], "--seed must be at least 0"),
                               (["--techniques", "nosuch"], "unknown techniques"),
                               (["--scenes", "nosuch"], "unknown scenes")):
            run = subprocess.run(tool + extra, capture_output=True, text=True, timeout=60)
            self.assertEqual(run.returncode, 2, extra)
            self.assertIn(message, run.stderr, extra)
        # A bake the library refuses: its message, exit 1.
        run = subprocess.run(tool + ["--size", "20000", "--repeats", "1"], capture_output=True, text=True, timeout=60)
        self.assertEqual(run.returncode, 1, run.stderr)
        self.assertIn("each side must be 1 to 16384", run.stderr)


if __name__ == "__main__":
    unittest.main()
