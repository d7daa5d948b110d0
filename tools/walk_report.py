#!/usr/bin/python3
"""Random-walk efficiency report: every technique on a set of scenes, RMSE against time, targets,
and mixtures of the techniques' components that show where the `auto` heuristic stands.

    /usr/bin/python3 tools/walk_report.py --cli build/dwivedi --out docs [--quick]

For every case x technique it runs `dwivedi estimate --json` on 2 threads with fixed seeds:

1. Efficiency: two calibration runs size the walk count for about 0.5 s a run (quick: 0.03 s);
   then 3 rounds (quick: 1) run every technique once each (seed = round + 1, the order rotated
   each round). Variance is pooled over the rounds; seconds per walk is the smallest of the
   rounds, the one least disturbed by other load on the machine (the same rule for every
   technique, so ratios within one run are fair). Efficiency = 1 / (variance x seconds per walk),
   by the wall clock as the issue defines it, and again by the CPU time of the process (all
   threads), which other load on a shared machine disturbs much less.
2. Reference per case: the Chandrasekhar value of tests/data/walk_reference.csv where it covers the
   case (the front-lit half-space), else a long run (seed 7777) of the case's most efficient
   technique. Every technique's pooled mean is shown as a z-score against it.
3. RMSE against time: each technique at 5 walk counts growing x4 (quick: 3) with 6 seeds (quick:
   3), RMSE of the estimates against the reference, log-log against the run's seconds; dashed, the
   prediction 1 / sqrt(efficiency x seconds) of step 1.
4. Mixtures (needs the build's libdwivedi_internal.a and a C compiler; skipped with
   --no-mixtures): a small program, compiled here against src/walk, runs the walks with any
   component weights (classical, poe, closest, incident, backward). It is first checked to give
   bit-identical results to the CLI for every named technique; then it measures sweeps of the
   classical share and of the incident/closest split, the current `auto` and the proposed
   weights, all relative to the best single technique of that case, within one run.

Writes into --out: walk_efficiency.md (tables, one PASS/FAIL line per target of the issue
"Random-walk estimators", section "Efficiency and speed"), walk_efficiency.json (every raw number)
and rmse_<case>.png. Needs matplotlib and numpy (Debian: python3-matplotlib python3-numpy, which
/usr/bin/python3 sees). Timings are only meaningful as ratios within one run; run nothing else
heavy meanwhile. Exits 1 with a one-line message if the CLI or the mixture program fails.
"""

import argparse
import csv
import datetime
import json
import math
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile

TOOLS_DIR = os.path.dirname(os.path.abspath(__file__))
SOURCE_DIR = os.path.dirname(TOOLS_DIR)
REFERENCE_CSV = os.path.join(SOURCE_DIR, "tests", "data", "walk_reference.csv")

TECHNIQUES = ("classical", "poe", "closest", "incident", "backward", "cycles", "auto")
# The order of dwvw_technique in src/walk/walk.h (and of dwv_technique_t), for the mixture program.
TECHNIQUE_IDS = {"auto": 0, "classical": 1, "poe": 2, "closest": 3, "incident": 4, "backward": 5, "cycles": 6}
COLORS = {"classical": "black", "poe": "tab:blue", "closest": "tab:orange", "incident": "tab:green",
          "backward": "tab:purple", "cycles": "tab:brown", "auto": "tab:red"}
THREADS = 2
SHAPE_IDS = {"halfspace": 0, "slab": 1, "sphere": 2}
LIGHT_IDS = {"front": 1, "back": 2}


class Case:
    """A scene of `dwivedi estimate`: grey medium, sigma_t 1, isotropic scattering, normal incidence."""

    anisotropy = 0.0

    def __init__(self, name, title, scene, albedo, light, thickness=1.0, radius=1.0):
        self.name, self.title, self.scene, self.albedo, self.light = name, title, scene, albedo, light
        self.thickness, self.radius = thickness, radius

    def arguments(self):
        extra = {"slab": ["--thickness", repr(self.thickness)], "sphere": ["--radius", repr(self.radius)]}
        return (["--scene", self.scene] + extra.get(self.scene, []) +
                ["--albedo", repr(self.albedo), "--light", self.light, "--incidence", "normal"])

    def describe(self):
        return {"name": self.name, "title": self.title, "scene": self.scene, "albedo": self.albedo,
                "light": self.light, "thickness": self.thickness if self.scene == "slab" else None,
                "radius": self.radius if self.scene == "sphere" else None, "anisotropy": self.anisotropy,
                "incidence": "normal"}


CASES = (
    Case("halfspace_a0.5", "front-lit half-space, albedo 0.5", "halfspace", 0.5, "front"),
    Case("halfspace_a0.9", "front-lit half-space, albedo 0.9", "halfspace", 0.9, "front"),
    Case("halfspace_a0.99", "front-lit half-space, albedo 0.99", "halfspace", 0.99, "front"),
    Case("halfspace_a0.999", "front-lit half-space, albedo 0.999", "halfspace", 0.999, "front"),
    Case("slab_d1", "back-lit slab, 1 mfp, albedo 0.99", "slab", 0.99, "back", thickness=1.0),
    Case("slab_d4", "back-lit slab, 4 mfp, albedo 0.99", "slab", 0.99, "back", thickness=4.0),
    Case("slab_d16", "back-lit slab, 16 mfp, albedo 0.99", "slab", 0.99, "back", thickness=16.0),
    Case("sphere_r4", "back-lit sphere, radius 4 mfp, albedo 0.99", "sphere", 0.99, "back", radius=4.0),
)
CASE_BY_NAME = {case.name: case for case in CASES}

MODES = {
    # seconds: target per efficiency run; rounds: efficiency runs per technique; reference_seconds:
    # the reference run; rmse_seconds: the largest RMSE run; rmse_sizes, rmse_seeds; mixture_*: the
    # same for the mixture sweeps.
    "full": {"seconds": 0.5, "rounds": 3, "reference_seconds": 4.0, "rmse_seconds": 0.3, "rmse_sizes": 5,
             "rmse_seeds": 6, "mixture_seconds": 0.3, "mixture_rounds": 3, "mixture_set": "full"},
    "quick": {"seconds": 0.03, "rounds": 1, "reference_seconds": 0.1, "rmse_seconds": 0.01, "rmse_sizes": 3,
              "rmse_seeds": 3, "mixture_seconds": 0.01, "mixture_rounds": 1, "mixture_set": "quick"},
}
EFFICIENCY_SEED = 1      # rounds use EFFICIENCY_SEED + round
CALIBRATION_SEED = 999
REFERENCE_SEED = 7777
RMSE_SEED = 1000         # RMSE runs use RMSE_SEED + seed index
MIXTURE_SEED = 2000      # mixture rounds use MIXTURE_SEED + round
VALIDATION_SEED = 5
VALIDATION_WALKS = 20000
CALIBRATION_WALKS = 2000
# Above this |z| a technique's mean disagrees with the reference: flagged in the table.
Z_FLAG = 5.0

# The targets of the issue, section "Efficiency and speed".
POE_OVER_CLASSICAL = {"halfspace_a0.99": 12.0, "halfspace_a0.999": 40.0}
SLAB_TARGET_CASE = "slab_d16"
INCIDENT_OVER_POE = 10.0
AUTO_OVER_POE = 5.0
AUTO_OVER_BEST = 0.5
EVENTS_PER_SECOND = 40e6
THROUGHPUT_CASES = ("halfspace_a0.99", "halfspace_a0.999")


class ReportError(Exception):
    """A failure the report explains in one line."""


def fail(message):
    print("walk_report: " + message, file=sys.stderr)
    sys.exit(1)


def import_plotting():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as pyplot
        import numpy
    except ImportError as error:
        fail("%s: this script needs matplotlib and numpy (Debian: apt-get install python3-matplotlib "
             "python3-numpy, then run it with /usr/bin/python3; this is %s)" % (error, sys.executable))
    return pyplot, numpy


def progress(message):
    print(message, flush=True)


# ---- running walks ------------------------------------------------------------------------------

def run_cli(cli, case, technique, walks, seed):
    command = ([cli, "estimate"] + case.arguments() +
               ["--technique", technique, "--walks", str(walks), "--seed", str(seed), "--threads", str(THREADS),
                "--json"])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    except OSError as error:
        raise ReportError("cannot run %s: %s" % (cli, error.strerror or error))
    except subprocess.TimeoutExpired:
        raise ReportError("%s timed out" % " ".join(command))
    if done.returncode != 0:
        raise ReportError("%s failed (%d): %s" % (" ".join(command), done.returncode,
                                                  done.stderr.strip().splitlines()[-1:] or ""))
    try:
        result = json.loads(done.stdout)
    except ValueError:
        raise ReportError("%s printed no JSON: %.200s" % (" ".join(command), done.stdout))
    if result.get("mean") is None or result.get("variance") is None:
        raise ReportError("%s gave a non-finite result: %s" % (" ".join(command), done.stdout.strip()))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # CPU time of the whole process, all threads (its start-up is a millisecond or two): unlike the
    # wall clock it does not grow while other programs hold the cores.
    result["cpu_seconds"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return result


def calibrate(run, target_seconds):
    """A walk count that takes about target_seconds: two probes, the second about a tenth of it."""
    walks = CALIBRATION_WALKS
    for fraction in (0.1, 1.0):
        seconds = max(run(walks, CALIBRATION_SEED)["seconds"], 1e-6)
        walks = int(min(max(walks * fraction * target_seconds / seconds, CALIBRATION_WALKS), 1e12))
    return walks


def pool(runs):
    """Pooled mean, variance and stderr of runs of one estimator (different seeds)."""
    walks = sum(r["walks"] for r in runs)
    total = sum(r["mean"] * r["walks"] for r in runs)
    squares = sum(r["variance"] * (r["walks"] - 1) + r["walks"] * r["mean"] ** 2 for r in runs)
    mean = total / walks
    variance = max(0.0, (squares - walks * mean * mean) / (walks - 1))
    return mean, variance, math.sqrt(variance / walks), walks


def summarise(runs):
    """The efficiency figures of one estimator from its rounds."""
    mean, variance, stderr, walks = pool(runs)
    per_walk = [r["seconds"] / r["walks"] for r in runs]
    seconds_per_walk = min(per_walk)
    events = sum(r["events"] for r in runs)
    events_per_walk = events / walks
    efficiency = 1.0 / (variance * seconds_per_walk) if variance > 0 else math.inf
    cpu_seconds_per_walk = min(r["cpu_seconds"] / r["walks"] for r in runs)
    return {
        "mean": mean, "stderr": stderr, "variance": variance, "walks": walks,
        "seconds_per_walk": seconds_per_walk, "seconds_per_walk_median": sorted(per_walk)[len(per_walk) // 2],
        "events_per_walk": events_per_walk,
        "ns_per_event": 1e9 * seconds_per_walk / events_per_walk if events else None,
        "events_per_second": events_per_walk / seconds_per_walk if events else None,
        "efficiency": efficiency,
        "cpu_seconds_per_walk": cpu_seconds_per_walk,
        "cpu_ns_per_event": 1e9 * cpu_seconds_per_walk / events_per_walk if events else None,
        "cpu_efficiency": 1.0 / (variance * cpu_seconds_per_walk) if variance > 0 and cpu_seconds_per_walk > 0
        else math.inf,
        "event_efficiency": 1.0 / (variance * events_per_walk) if variance > 0 and events else math.inf,
        "round_efficiencies": [1.0 / (r["variance"] * r["seconds"] / r["walks"]) if r["variance"] > 0 else None
                               for r in runs],
        "truncated_walks": sum(r.get("truncated_walks", 0) for r in runs),
    }


def best_technique(measured, key="efficiency"):
    """The most efficient technique of a case other than auto (whose target is relative to it)."""
    return max((t for t in TECHNIQUES if t != "auto"), key=lambda t: measured[t][key])


# ---- the reference ------------------------------------------------------------------------------

REFERENCE_COLUMNS = ("quantity", "shape", "incidence", "cosine", "albedo", "value", "remainder_bound")


def read_reference_table():
    """Rows of tests/data/walk_reference.csv (tools/gen_walk_reference.py) as dicts, or None if
    there is no such file; ReportError if it lacks the columns read here."""
    if not os.path.exists(REFERENCE_CSV):
        return None
    with open(REFERENCE_CSV, encoding="utf-8") as table:
        lines = [line for line in table if line.strip() and not line.lstrip().startswith("#")]
    rows = list(csv.DictReader(lines))
    missing = [c for c in REFERENCE_COLUMNS if not rows or c not in rows[0]]
    if missing:
        raise ReportError("%s lacks the column(s) %s" % (REFERENCE_CSV, ", ".join(missing)))
    return rows


def reference_from_table(rows, case):
    """(value, remainder_bound) of the table's Chandrasekhar reflectance for a front-lit half-space
    at normal incidence, or None for other cases (the table's slab values are for low albedos)."""
    if case.scene != "halfspace" or case.light != "front" or not rows:
        return None
    for row in rows:
        try:
            if (row["quantity"] == "reflectance" and row["shape"] == "halfspace" and row["incidence"] == "cosine"
                    and float(row["cosine"]) == 1.0 and float(row["albedo"]) == case.albedo):
                return float(row["value"]), float(row["remainder_bound"])
        except ValueError:
            raise ReportError("%s: a malformed row: %s" % (REFERENCE_CSV, row))
    return None


# ---- the mixture program ------------------------------------------------------------------------

# Reads one request per line and prints one JSON object per line:
#   T shape thickness radius albedo light walks seed threads technique   (a named technique)
#   W shape thickness radius albedo light walks seed threads qc qpoe qclosest qincident qbackward
# It sets up the walks as src/api/walk_api.c does for dwv_estimate (grey medium, g = 0, normal
# incidence, the shape's lit patches) and, for W, overwrites the guide's component weights.
MIXTURE_PROGRAM = r"""
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "walk/estimate.h"

static double cpu_seconds(void)
{
    struct timespec now;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

int main(void)
{
    char line[1024];
    while (fgets(line, sizeof line, stdin)) {
        char kind;
        int shape, light, technique = 0;
        double thickness, radius, albedo, q[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
        unsigned long long walks, seed;
        unsigned threads;
        int read = sscanf(line, "%c %d %lf %lf %lf %d %llu %llu %u", &kind, &shape, &thickness, &radius, &albedo,
                          &light, &walks, &seed, &threads);
        const char *rest = line;
        for (int field = 0; field < 9 && rest; ++field) rest = strchr(rest + 1, ' ');
        int ok = read == 9 && rest;
        if (ok && kind == 'T') ok = sscanf(rest, "%d", &technique) == 1;
        else if (ok && kind == 'W') ok = sscanf(rest, "%lf %lf %lf %lf %lf", &q[0], &q[1], &q[2], &q[3], &q[4]) == 5;
        else ok = 0;
        if (!ok) {
            fprintf(stderr, "mixture program: bad request: %s", line);
            return 2;
        }
        dwvw_estimate_setup setup;
        memset(&setup, 0, sizeof setup);
        setup.shape.kind = (dwvw_shape_kind)shape;
        setup.shape.thickness = thickness;
        setup.shape.radius = radius;
        double sigma_t[3] = {1.0, 1.0, 1.0}, albedos[3] = {albedo, albedo, albedo};
        dwvw_medium_init(&setup.medium, 1, sigma_t, albedos, 0.0);
        setup.incidence_diffuse = 0;
        setup.incidence_cosine = 1.0;
        setup.light = light;
        setup.walks = walks;
        setup.seed = seed;
        setup.threads = threads;
        setup.max_events = 1000000u;
        dwvw_light_patch patches[DWVW_MAX_PATCHES];
        int patch_count = dwvw_estimate_light_patches(&setup.shape, light, patches);
        dwvw_guide_init(&setup.guide, kind == 'T' ? (dwvw_technique)technique : DWVW_INCIDENT, &setup.medium,
                        patches, patch_count);
        if (kind == 'W') {
            setup.guide.q_classical = q[0];
            setup.guide.q_poe = q[1];
            setup.guide.q_closest = q[2];
            setup.guide.q_incident = q[3];
            setup.guide.q_backward = q[4];
        }
        dwvw_estimate_totals totals;
        double cpu_start = cpu_seconds();
        int failed = dwvw_estimate_run(&setup, &totals) != 0;
        double cpu = cpu_seconds() - cpu_start;
        if (failed) {
            fprintf(stderr, "mixture program: the run failed\n");
            return 1;
        }
        /* The same arithmetic as dwv_estimate in src/api/walk_api.c. */
        double n = (double)walks, mean = totals.sum[0] / n;
        double variance = totals.m2[0] / (n - 1.0); /* as dwv_estimate (src/api/walk_api.c) */
        printf("{\"mean\": %.17g, \"variance\": %.17g, \"walks\": %llu, \"events\": %llu, \"seconds\": %.17g, "
               "\"cpu_seconds\": %.17g, \"truncated_walks\": %llu, \"patches\": %d, "
               "\"q\": [%.17g, %.17g, %.17g, %.17g, %.17g]}\n",
               mean, variance, walks, (unsigned long long)totals.events, totals.seconds, cpu,
               (unsigned long long)totals.truncated_walks, patch_count, setup.guide.q_classical, setup.guide.q_poe,
               setup.guide.q_closest, setup.guide.q_incident, setup.guide.q_backward);
        fflush(stdout);
    }
    return 0;
}
"""


def c_compiler(build_dir):
    """The build's C compiler (CMakeCache.txt), else cc from PATH."""
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if os.path.exists(cache):
        with open(cache, encoding="utf-8", errors="replace") as text:
            for line in text:
                if line.startswith("CMAKE_C_COMPILER:"):
                    return line.split("=", 1)[1].strip()
    return shutil.which("cc")


def sanitizer_flags(build_dir):
    """The sanitizer flags of a DWV_SANITIZE build (CMakeCache.txt): its archive needs their runtime."""
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if os.path.exists(cache):
        with open(cache, encoding="utf-8", errors="replace") as text:
            for line in text:
                if line.startswith("DWV_SANITIZE:") and line.split("=", 1)[1].strip().upper() in ("ON", "1", "TRUE", "YES"):
                    return ["-fsanitize=address,undefined", "-fno-sanitize-recover=all"]
    return []


class MixtureProgram:
    """The compiled mixture program, kept running; one request at a time."""

    def __init__(self, archive, directory):
        self.archive = archive
        build_dir = os.path.dirname(os.path.abspath(archive))
        compiler = c_compiler(build_dir)
        if not compiler:
            raise ReportError("no C compiler to build the mixture program (use --no-mixtures)")
        source = os.path.join(directory, "walk_mixture.c")
        self.path = os.path.join(directory, "walk_mixture")
        with open(source, "w", encoding="ascii") as out:
            out.write(MIXTURE_PROGRAM)
        command = [compiler, "-O2", "-std=c11", "-I", os.path.join(SOURCE_DIR, "src"), "-I",
                   os.path.join(SOURCE_DIR, "capi"), source, archive, "-lm", "-pthread", "-o", self.path] + sanitizer_flags(build_dir)
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise ReportError("could not build the mixture program against %s: %s"
                              % (archive, " ".join(done.stderr.strip().splitlines()[:3])))
        self.process = subprocess.Popen([self.path], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True)

    def request(self, line):
        self.process.stdin.write(line + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        if not answer:
            raise ReportError("the mixture program stopped: %s" % self.process.stderr.read().strip())
        return json.loads(answer)

    @staticmethod
    def _head(kind, case, walks, seed):
        return "%s %d %r %r %r %d %d %d %d" % (kind, SHAPE_IDS[case.scene], case.thickness, case.radius, case.albedo,
                                               LIGHT_IDS[case.light], walks, seed, THREADS)

    def technique(self, case, technique, walks, seed):
        return self.request(self._head("T", case, walks, seed) + " %d" % TECHNIQUE_IDS[technique])

    def weights(self, case, q, walks, seed):
        return self.request(self._head("W", case, walks, seed) + " " + " ".join("%.17g" % x for x in q))

    def close(self):
        self.process.stdin.close()
        self.process.wait(timeout=60)


def proposed_weights(case, patch_count):
    """The heuristic this report proposes for `auto` (see docs/walk.md), as component weights
    (classical, poe, closest, incident, backward). Below albedo 0.2, classical only, as now. Else a
    classical share of min(0.01, 0.1 sqrt(1 - albedo)), raised to |g| for anisotropic media as now:
    the variance a classical share q adds grows with q and with the events per walk n, and a guided
    walk from a flat surface has n ~ 1.4 / sqrt(1 - albedo) events, so the cap keeps the classical
    steps per walk, q n, below about 0.14, where the measured variance grows by 3 per cent or less,
    as the albedo goes to 1. The guided rest goes all to the lit patches when there are any, to the
    closest point when there are none."""
    if case.albedo < 0.2:
        return (1.0, 0.0, 0.0, 0.0, 0.0)
    classical = max(min(0.01, 0.1 * math.sqrt(1.0 - case.albedo)), abs(case.anisotropy))
    guided = 1.0 - classical
    if patch_count > 0:
        return (classical, 0.0, 0.0, guided, 0.0)
    return (classical, 0.0, guided, 0.0, 0.0)


def split(classical, incident_fraction):
    """Classical share `classical`; the guided rest split incident : closest."""
    guided = 1.0 - classical
    return (classical, 0.0, guided * (1.0 - incident_fraction), guided * incident_fraction, 0.0)


def mixture_set(which):
    """(label, kind, weights) of the mixtures measured per case, kind 'sweep' or 'split'."""
    if which == "quick":
        return [("classical 0, incident 1", "sweep", split(0.0, 1.0)),
                ("classical 0.1, incident 0.6, closest 0.3", "split", split(0.1, 2.0 / 3.0))]
    mixtures = []
    for classical in (0.0, 0.003, 0.01, 0.03, 0.1, 0.3):
        mixtures.append(("classical %g, incident rest" % classical, "sweep", split(classical, 1.0)))
    for fraction, name in ((0.0, "0"), (1.0 / 3.0, "1/3"), (2.0 / 3.0, "2/3")):
        mixtures.append(("classical 0.01, incident %s of the rest, closest the rest" % name, "split",
                         split(0.01, fraction)))
    return mixtures


def validate_mixture_program(program, cli):
    """The mixture program against the CLI: bit-identical estimates for every named technique, and
    for `auto`'s own weights given as numbers. A stale build or a changed setup shows here."""
    checks = []
    for case in (CASE_BY_NAME["halfspace_a0.99"], CASE_BY_NAME["slab_d4"], CASE_BY_NAME["sphere_r4"]):
        for technique in TECHNIQUES:
            ours = program.technique(case, technique, VALIDATION_WALKS, VALIDATION_SEED)
            theirs = run_cli(cli, case, technique, VALIDATION_WALKS, VALIDATION_SEED)
            same = (ours["mean"] == theirs["mean"] and ours["variance"] == theirs["variance"]
                    and ours["events"] == theirs["events"])
            checks.append({"case": case.name, "technique": technique, "identical": same,
                           "program_mean": ours["mean"], "cli_mean": theirs["mean"], "weights": ours["q"]})
            if not same:
                raise ReportError("the mixture program (built against %s) does not reproduce `dwivedi estimate` "
                                  "for %s on %s (mean %r against %r): rebuild the library, or use --no-mixtures"
                                  % (program.archive, technique, case.name, ours["mean"], theirs["mean"]))
            if technique == "auto":
                again = program.weights(case, ours["q"], VALIDATION_WALKS, VALIDATION_SEED)
                if again["mean"] != ours["mean"] or again["variance"] != ours["variance"]:
                    raise ReportError("the mixture program's weights mode differs from `auto` at auto's own weights "
                                      "on %s" % case.name)
    return checks


# ---- the stages ---------------------------------------------------------------------------------

def efficiency_stage(cli, mode):
    results = {}
    for case in CASES:
        walks = {t: calibrate(lambda w, s, t=t: run_cli(cli, case, t, w, s), mode["seconds"]) for t in TECHNIQUES}
        runs = {t: [] for t in TECHNIQUES}
        for round_index in range(mode["rounds"]):
            shift = round_index % len(TECHNIQUES)
            for technique in TECHNIQUES[shift:] + TECHNIQUES[:shift]:
                runs[technique].append(run_cli(cli, case, technique, walks[technique], EFFICIENCY_SEED + round_index))
        results[case.name] = {t: dict(summarise(runs[t]), runs=runs[t], calibrated_walks=walks[t])
                              for t in TECHNIQUES}
        best = best_technique(results[case.name])
        progress("efficiency %-17s best %-9s %s" % (case.name, best, "  ".join(
            "%s %.3g" % (t, results[case.name][t]["efficiency"]) for t in TECHNIQUES)))
    return results


def reference_stage(cli, mode, efficiency, table_rows):
    references = {}
    for case in CASES:
        measured = efficiency[case.name]
        best = best_technique(measured, "cpu_efficiency")
        walks = max(CALIBRATION_WALKS, int(mode["reference_seconds"] / measured[best]["seconds_per_walk"]))
        run = run_cli(cli, case, best, walks, REFERENCE_SEED)
        entry = {"walk_technique": best, "walk_mean": run["mean"], "walk_stderr": run["stderr"], "walk_walks": walks,
                 "walk_seconds": run["seconds"]}
        tabled = reference_from_table(table_rows, case)
        if tabled:
            value, remainder = tabled
            # The exact value lies in [value, value + remainder]; for the half-space remainder is 0.
            entry.update(source="Chandrasekhar, tests/data/walk_reference.csv", value=value + remainder / 2,
                         stderr=remainder / 2, walk_z=(run["mean"] - value) / run["stderr"] if run["stderr"] > 0
                         else None)
        else:
            entry.update(source="walks: %s, %d walks, seed %d" % (best, walks, REFERENCE_SEED), value=run["mean"],
                         stderr=run["stderr"])
        references[case.name] = entry
        for technique in TECHNIQUES:
            r = measured[technique]
            spread = math.hypot(r["stderr"], entry["stderr"])
            r["z"] = (r["mean"] - entry["value"]) / spread if spread > 0 else None
        progress("reference  %-17s %.8g +- %.2g (%s)%s" % (case.name, entry["value"], entry["stderr"], entry["source"],
                                                            reference_check(entry)))
    return references


def rmse_stage(cli, mode, efficiency, references):
    curves = {}
    for case in CASES:
        reference = references[case.name]["value"]
        curves[case.name] = {}
        for technique in TECHNIQUES:
            per_walk = efficiency[case.name][technique]["seconds_per_walk"]
            top = max(2, int(mode["rmse_seconds"] / per_walk))
            sizes = sorted({max(2, top // 4 ** k) for k in range(mode["rmse_sizes"])})
            points = []
            for walks in sizes:
                runs = [run_cli(cli, case, technique, walks, RMSE_SEED + s) for s in range(mode["rmse_seeds"])]
                errors = [r["mean"] - reference for r in runs]
                seconds = sorted(r["seconds"] for r in runs)
                points.append({"walks": walks, "seconds_median": seconds[len(seconds) // 2],
                               "rmse": math.sqrt(sum(e * e for e in errors) / len(errors)),
                               "means": [r["mean"] for r in runs], "seconds": [r["seconds"] for r in runs]})
            curves[case.name][technique] = points
        progress("rmse       %-17s done" % case.name)
    return curves


def mixture_stage(program, mode, efficiency):
    results = {}
    for case in CASES:
        measured = efficiency[case.name]
        # The best by CPU time: the less noisy choice on a shared machine.
        best = best_technique(measured, "cpu_efficiency")
        patches = program.technique(case, "auto", CALIBRATION_WALKS, CALIBRATION_SEED)["patches"]
        entries = [("best single technique: %s" % best, "technique", best),
                   ("auto (as built)", "technique", "auto"),
                   ("proposed auto", "proposed", proposed_weights(case, patches))]
        entries += [(label, kind, q) for label, kind, q in mixture_set(mode["mixture_set"])]

        def run(entry, walks, seed):
            _, kind, what = entry
            if kind == "technique":
                return program.technique(case, what, walks, seed)
            return program.weights(case, what, walks, seed)

        walks = [calibrate(lambda w, s, e=e: run(e, w, s), mode["mixture_seconds"]) for e in entries]
        runs = [[] for _ in entries]
        for round_index in range(mode["mixture_rounds"]):
            shift = round_index % len(entries)
            for index in list(range(shift, len(entries))) + list(range(shift)):
                runs[index].append(run(entries[index], walks[index], MIXTURE_SEED + round_index))
        rows = []
        for (label, kind, _), entry_runs in zip(entries, runs):
            summary = summarise(entry_runs)
            rows.append(dict(summary, label=label, kind=kind, weights=entry_runs[0]["q"], runs=entry_runs))
        best_row = rows[0]
        for row in rows:
            row["relative_to_best"] = row["efficiency"] / best_row["efficiency"]
            row["cpu_relative_to_best"] = row["cpu_efficiency"] / best_row["cpu_efficiency"]
            row["variance_relative_to_best"] = row["variance"] / best_row["variance"]
            row["event_relative_to_best"] = row["event_efficiency"] / best_row["event_efficiency"]
        results[case.name] = rows
        progress("mixtures   %-17s auto %.2f, proposed %.2f of %s" % (case.name, rows[1]["relative_to_best"],
                                                                      rows[2]["relative_to_best"], best))
    return results


# ---- targets ------------------------------------------------------------------------------------

def evaluate_targets(efficiency):
    """One entry per target: the measured figure by the wall clock (which decides PASS, as the
    issue defines efficiency by it) and the same figure by CPU time, which other load on the
    machine disturbs less."""
    targets = []

    def ratio(e, numerator, denominator, key):
        return e[numerator][key] / e[denominator][key]

    def add(name, wall, cpu, threshold, unit):
        targets.append({"target": name, "measured": wall, "measured_cpu": cpu, "threshold": threshold,
                        "pass": wall is not None and wall >= threshold, "unit": unit})

    for case_name, threshold in POE_OVER_CLASSICAL.items():
        e = efficiency[case_name]
        add("poe / classical efficiency, %s" % CASE_BY_NAME[case_name].title,
            ratio(e, "poe", "classical", "efficiency"), ratio(e, "poe", "classical", "cpu_efficiency"), threshold, "x")
    slab = efficiency[SLAB_TARGET_CASE]
    for technique, threshold in (("incident", INCIDENT_OVER_POE), ("auto", AUTO_OVER_POE)):
        add("%s / poe efficiency, %s" % (technique, CASE_BY_NAME[SLAB_TARGET_CASE].title),
            ratio(slab, technique, "poe", "efficiency"), ratio(slab, technique, "poe", "cpu_efficiency"), threshold,
            "x")
    for case in CASES:
        e = efficiency[case.name]
        best, best_cpu = best_technique(e), best_technique(e, "cpu_efficiency")
        add("auto / best (%s; by CPU time %s) efficiency, %s" % (best, best_cpu, case.title),
            ratio(e, "auto", best, "efficiency"), ratio(e, "auto", best_cpu, "cpu_efficiency"), AUTO_OVER_BEST, "x")
    for case_name in THROUGHPUT_CASES:
        poe = efficiency[case_name]["poe"]
        # By CPU time: THREADS threads each busy all the time.
        add("poe scattering events per second on %d threads, %s" % (THREADS, CASE_BY_NAME[case_name].title),
            poe["events_per_second"], THREADS * 1e9 / poe["cpu_ns_per_event"] if poe["cpu_ns_per_event"] else None,
            EVENTS_PER_SECOND, " events/s")
    return targets


# ---- output -------------------------------------------------------------------------------------

def plot_rmse(pyplot, numpy, case, curves, efficiency, reference, path):
    figure, axes = pyplot.subplots(figsize=(7.0, 5.0), dpi=100)
    for technique in TECHNIQUES:
        points = curves[technique]
        seconds = numpy.array([p["seconds_median"] for p in points])
        rmse = numpy.array([p["rmse"] for p in points])
        shown = rmse > 0
        axes.loglog(seconds[shown], rmse[shown], "o-", color=COLORS[technique], label=technique, markersize=4)
        e = efficiency[technique]["efficiency"]
        if math.isfinite(e) and e > 0:
            t = numpy.geomspace(seconds.min(), seconds.max(), 20)
            axes.loglog(t, 1.0 / numpy.sqrt(e * t), "--", color=COLORS[technique], linewidth=0.8, alpha=0.7)
    if reference["stderr"] > 0:
        axes.axhline(reference["stderr"], color="grey", linestyle=":", linewidth=1.0,
                     label="reference stderr (%s)" % reference["walk_technique"])
    axes.set_xlabel("seconds per estimate (wall clock, %d threads)" % THREADS)
    axes.set_ylabel("RMSE against the reference")
    axes.set_title("%s\nreference %.6g (%s)" % (case.title, reference["value"], reference["source"].split(":")[0]),
                   fontsize=10)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8, ncol=2, title="dashed: 1/sqrt(efficiency x seconds)", title_fontsize=7)
    figure.tight_layout()
    figure.savefig(path)
    pyplot.close(figure)


def number(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return "%.*g" % (digits, x)


def reference_check(reference):
    """Where the reference is Chandrasekhar's, how the long walk run agrees with it."""
    if reference.get("walk_z") is None:
        return ""
    return "; the long run of %s (%d walks) gives %.8g +- %.2g, z = %.2f" % (
        reference["walk_technique"], reference["walk_walks"], reference["walk_mean"], reference["walk_stderr"],
        reference["walk_z"])


def write_markdown(path, meta, efficiency, references, targets, mixtures, validation):
    lines = ["# Random-walk efficiency", "",
             "Written by `tools/walk_report.py` (%s mode) on %s: `dwivedi estimate --json`, %d threads, fixed seeds. "
             "Machine: %s, %d cores; load average %s before, %s after. Efficiency = 1 / (variance x seconds per "
             "walk), seconds per walk the least of %d rounds (see the script's header); ratios within this run "
             "are what count." % (meta["mode"], meta["date"], THREADS, meta["machine"], meta["cores"],
                                   meta["load_before"], meta["load_after"], meta["rounds"]), "",
             "## Targets", "",
             "PASS or FAIL by the wall clock, as the issue defines efficiency; the CPU-time column is the same "
             "figure with CPU seconds (all threads) in place of wall seconds, which other load on the machine "
             "disturbs less (for events/s: %d threads each busy all the time)." % THREADS, "",
             "| target | measured (wall) | by CPU time | threshold | |", "|---|---|---|---|---|"]
    for t in targets:
        lines.append("| %s | %s%s | %s%s | %s%s | %s |" % (
            t["target"], number(t["measured"]), t["unit"], number(t["measured_cpu"]), t["unit"],
            number(t["threshold"]), t["unit"], "PASS" if t["pass"] else "FAIL"))
    lines += ["", "## Efficiency per case", "",
              "mean +- stderr pooled over the rounds; z against the reference (|z| > %g marked !); ns/event: wall "
              "clock on %d threads, and CPU time (all threads) per event; efficiency = 1 / (variance x wall seconds "
              "per walk), relative to classical (eff/cl) and to the best technique of the case (eff/best); "
              "cpu/best: the same with CPU seconds." % (Z_FLAG, THREADS), ""]
    for case in CASES:
        e = efficiency[case.name]
        ref = references[case.name]
        best = e[best_technique(e)]["efficiency"]
        best_cpu = e[best_technique(e, "cpu_efficiency")]["cpu_efficiency"]
        lines += ["### %s" % case.title, "",
                  "Reference %.8g +- %.2g (%s)%s. Plot: [rmse_%s.png](rmse_%s.png)" % (
                      ref["value"], ref["stderr"], ref["source"], reference_check(ref), case.name, case.name), "",
                  "| technique | mean +- stderr | z | variance | events/walk | ns/event wall | ns/event CPU | events/s "
                  "| efficiency | eff/cl | eff/best | cpu/best |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for technique in TECHNIQUES:
            r = e[technique]
            z = r.get("z")
            lines.append("| %s | %.6f +- %.2g | %s%s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                technique, r["mean"], r["stderr"], number(z, 2), " !" if z is not None and abs(z) > Z_FLAG else "",
                number(r["variance"]), number(r["events_per_walk"]), number(r["ns_per_event"]),
                number(r["cpu_ns_per_event"]), number(r["events_per_second"]), number(r["efficiency"]),
                number(r["efficiency"] / e["classical"]["efficiency"]), number(r["efficiency"] / best, 2),
                number(r["cpu_efficiency"] / best_cpu, 2)))
        lines.append("")
    lines += ["## Mixtures", ""]
    if mixtures is None:
        lines += ["Not measured in this run (--no-mixtures).", ""]
    else:
        lines += ["Component weights (classical, poe, closest, incident, backward), run by the mixture program "
                  "built against the build's libdwivedi_internal.a, first checked to reproduce `dwivedi estimate` "
                  "bit for bit for %d technique x case pairs and for `auto` at its own weights given as numbers. "
                  "Efficiency relative to the best single technique of the case, measured in the same stage: by "
                  "wall and by CPU seconds per walk, and by events per walk (1 / (variance x events per walk), "
                  "blind to what an event costs but free of timing noise)." %
                  len(validation), ""]
        for case in CASES:
            lines += ["### %s" % case.title, "",
                      "| mixture | weights | variance | events/walk | ns/event wall | ns/event CPU | eff/best (wall) "
                      "| eff/best (CPU) | variance/best | eff/best (events) |",
                      "|---|---|---|---|---|---|---|---|---|---|"]
            for row in mixtures[case.name]:
                lines.append("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
                    row["label"], ", ".join("%.3g" % q for q in row["weights"]), number(row["variance"]),
                    number(row["events_per_walk"]), number(row["ns_per_event"]), number(row["cpu_ns_per_event"]),
                    number(row["relative_to_best"], 2), number(row["cpu_relative_to_best"], 2),
                    number(row["variance_relative_to_best"], 3), number(row["event_relative_to_best"], 2)))
            lines.append("")
    with open(path, "w", encoding="utf-8") as out:
        out.write("\n".join(lines))


def to_json(value, indent=""):
    """JSON with objects one key a line, but lists and objects of plain values (a run's figures, a
    list of numbers) on one line: readable, and small."""
    inner = indent + " "
    if isinstance(value, dict):
        if all(not isinstance(v, (dict, list, tuple)) or (isinstance(v, (list, tuple)) and
                                                            all(not isinstance(x, (dict, list, tuple)) for x in v))
               for v in value.values()) and len(value) <= 12:
            return json.dumps(value, allow_nan=False)
        return "{\n" + ",\n".join(inner + json.dumps(k) + ": " + to_json(v, inner) for k, v in value.items()) + \
            "\n" + indent + "}"
    if isinstance(value, (list, tuple)):
        if all(not isinstance(v, (dict, list, tuple)) for v in value):
            return json.dumps(list(value), allow_nan=False)
        return "[\n" + ",\n".join(inner + to_json(v, inner) for v in value) + "\n" + indent + "]"
    return json.dumps(value, allow_nan=False)


def finite(value):
    """The report with every non-finite float as null (JSON has no infinities)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    return value


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cli", required=True, help="the dwivedi executable")
    parser.add_argument("--out", required=True, help="directory for walk_efficiency.md/.json and rmse_*.png")
    parser.add_argument("--quick", action="store_true", help="tiny runs (for CI): the plumbing, not the figures")
    parser.add_argument("--internal-lib", help="libdwivedi_internal.a for the mixture program (default: next to --cli)")
    parser.add_argument("--no-mixtures", action="store_true", help="skip the mixture sweeps")
    options = parser.parse_args()

    cli = os.path.abspath(options.cli)
    if not (os.path.isfile(cli) and os.access(cli, os.X_OK)):
        fail("%s is not an executable dwivedi CLI" % cli)
    archive = options.internal_lib or os.path.join(os.path.dirname(cli), "libdwivedi_internal.a")
    if not options.no_mixtures and not os.path.isfile(archive):
        fail("%s not found: build the dwivedi_internal target, pass --internal-lib, or use --no-mixtures" % archive)
    pyplot, numpy = import_plotting()
    mode_name = "quick" if options.quick else "full"
    mode = MODES[mode_name]
    os.makedirs(options.out, exist_ok=True)

    try:
        table_rows = read_reference_table()
    except (OSError, csv.Error) as error:
        fail("cannot read %s: %s" % (REFERENCE_CSV, error))
    except ReportError as error:
        fail(str(error))
    meta = {"mode": mode_name, "date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M"),
            "machine": platform.processor() or platform.machine(), "cores": os.cpu_count(),
            "load_before": "%.2f" % os.getloadavg()[0], "rounds": mode["rounds"], "cli": cli, "threads": THREADS,
            "settings": mode}
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            for line in info:
                if line.startswith("model name"):
                    meta["machine"] = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass

    started = datetime.datetime.now()
    stage_seconds = {}

    def timed(name, stage, *arguments):
        begun = datetime.datetime.now()
        result = stage(*arguments)
        stage_seconds[name] = (datetime.datetime.now() - begun).total_seconds()
        return result

    mixtures = validation = program = None
    try:
        with tempfile.TemporaryDirectory() as directory:
            try:
                if not options.no_mixtures:
                    # First, so that a stale build fails in seconds, not after the long stages.
                    program = MixtureProgram(archive, directory)
                    validation = validate_mixture_program(program, cli)
                    progress("mixture program reproduces the CLI bit for bit (%d checks)" % len(validation))
                efficiency = timed("efficiency", efficiency_stage, cli, mode)
                references = timed("reference", reference_stage, cli, mode, efficiency, table_rows)
                curves = timed("rmse", rmse_stage, cli, mode, efficiency, references)
                if program:
                    mixtures = timed("mixtures", mixture_stage, program, mode, efficiency)
            finally:
                if program:
                    program.close()
    except ReportError as error:
        fail(str(error))
    meta["load_after"] = "%.2f" % os.getloadavg()[0]
    meta["wall_seconds"] = (datetime.datetime.now() - started).total_seconds()
    meta["stage_seconds"] = stage_seconds
    targets = evaluate_targets(efficiency)

    for case in CASES:
        plot_rmse(pyplot, numpy, case, curves[case.name], efficiency[case.name], references[case.name],
                  os.path.join(options.out, "rmse_%s.png" % case.name))
    write_markdown(os.path.join(options.out, "walk_efficiency.md"), meta, efficiency, references, targets, mixtures,
                   validation or [])
    report = {"meta": meta, "cases": [case.describe() for case in CASES], "techniques": list(TECHNIQUES),
              "efficiency": efficiency, "references": references, "rmse": curves, "targets": targets,
              "mixtures": mixtures, "mixture_validation": validation}
    with open(os.path.join(options.out, "walk_efficiency.json"), "w", encoding="utf-8") as out:
        out.write(to_json(finite(report)))
        out.write("\n")

    for t in targets:
        progress("%s  %s: %s (threshold %s)" % ("PASS" if t["pass"] else "FAIL", t["target"], number(t["measured"]),
                                               number(t["threshold"])))
    progress("ns per event (wall, %d threads): " % THREADS)
    for case in CASES:
        progress("  %-17s %s" % (case.name, "  ".join("%s %s" % (t, number(efficiency[case.name][t]["ns_per_event"]))
                                                       for t in TECHNIQUES)))
    progress("wrote %s in %.0f s (%s)" % (options.out, meta["wall_seconds"], ", ".join(
        "%s %.0f s" % item for item in stage_seconds.items())))


if __name__ == "__main__":
    main()
