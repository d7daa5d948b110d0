#!/usr/bin/env python3
"""Runs a test script of tests/blender in one Blender: the host's, or the one in a clean Debian
chroot made by scripts/blender-chroots.sh (trixie: Blender 4.3, sid: Blender 5.2). The one way
the tests and tools/cycles_report.py run Blender in a chroot (make_chroot, blender_command).

    python3 tests/blender/run_package_tests.py --blender host|trixie|sid --build-dir build
            [--script test_package.py|test_fidelity.py|test_farm.py|...] [--ui] [--work DIR]

--script (default test_package.py): the script, run with harness.py, scenes.py and uv_bakes.py beside it; it
installs the package the build made for that Blender (3.x: the legacy zip, 4.2+: the extension)
itself. test_fidelity.py compares the bakes with that Blender's Cycles; its figures
(fidelity_figures.json) are copied to WORK, pass or fail. --ui runs test_ui.py instead, in
Blender's real UI in a window on Xvfb.

Steps, each timed (printed at the end and written to WORK/times.json):
1. test_package.py only: the bad library files (tests/blender/fixtures.py) with the C compiler
   and clang + ld.lld;
2. for a chroot: the chroot (made once and reused: scripts/blender-chroots.sh), and a scratch
   folder inside it, CHROOT/tmp/dwivedi-test-..., with copies of the two packages, the test
   scripts and the fixtures. If the packaged library still links libraries other than glibc,
   libstdc++ and libgcc (a library that is not yet self-contained), copies of the host's
   (Debian 12's) are put in that scratch folder's deps/ and loaded by the test before the bake:
   a scratch test set-up only, never in a package, said on stdout;
3. Blender: `blender -b --factory-startup --python-exit-code 1 --python SCRIPT` with its
   user folders and TMPDIR in the scratch folder; with --ui, `xvfb-run blender --factory-startup
   --enable-event-simulate --python test_ui.py` (xvfb and xauth: scripts/setup.sh on the host,
   the chroots' package list in scripts/blender-chroots.sh). As root it runs under `unshare --mount
   --propagation private`: /proc is mounted for it in that namespace (chroot) and the test may
   bind-mount the add-on folder read-only there; every mount goes away with the namespace, on
   failure too;
4. the verdict: exit status 0, every step passed (for --ui: "passed" in the times file the test
   writes, since the UI quits through wm.quit_blender), and no crash report (*.crash.txt in its
   TMPDIR or /tmp) written while it ran.
Exit status 0 only if all of that holds; 1 with a message otherwise (a chroot that cannot be made
is a failure, never a skip).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
HERE = ROOT / "tests" / "blender"
sys.path.insert(0, str(ROOT / "blender_addon" / "dwivedi_bake"))
import libcheck  # noqa: E402  (standard library only)

# What any Linux newer than Debian 12 has: the library may link these and nothing else.
BASE_LIBRARIES = {"libc.so.6", "libm.so.6", "libstdc++.so.6", "libgcc_s.so.1", "ld-linux-x86-64.so.2",
                  "libpthread.so.0", "libdl.so.2", "librt.so.1"}
TIMES = {}
# The headless test scripts of tests/blender this runner can run (test_ui.py: with --ui).
SCRIPTS = tuple(sorted(p.name for p in Path(__file__).resolve().parent.glob("test_*.py") if p.name != "test_ui.py"))
# Passed on to test_fidelity.py and test_indirect.py (their settings, for a diagnosis run; CI uses their defaults).
FIDELITY_SETTINGS = ("DWIVEDI_FIDELITY_EVENT_CAP", "DWIVEDI_FIDELITY_ONLY", "DWIVEDI_FIDELITY_RESOLUTION",
                     "DWIVEDI_FIDELITY_CYCLES_SPP", "DWIVEDI_FIDELITY_DWIVEDI_SPP", "DWIVEDI_FOOTPRINT_PLANTED",
                     "DWIVEDI_INDIRECT_ONLY", "DWIVEDI_INDIRECT_PLANTED",
                     "DWIVEDI_INDIRECT_SEEDS", "DWIVEDI_INDIRECT_RESOLUTION", "DWIVEDI_INDIRECT_CYCLES_SPP",
                     "DWIVEDI_INDIRECT_DWIVEDI_SPP")


def fail(message):
    print(f"run_package_tests: {message}", file=sys.stderr)
    sys.exit(1)


def step(name, function, *args):
    start = time.monotonic()
    try:
        return function(*args)
    finally:
        TIMES[name] = round(time.monotonic() - start, 1)


def extension_zip(build_dir):
    found = sorted(build_dir.glob("dwivedi_bake-*-linux-x64.zip"))
    if len(found) != 1:
        fail(f"expected one extension package build/dwivedi_bake-<version>-linux-x64.zip in {build_dir}, found "
             f"{[p.name for p in found]} (build the dwivedi_bake_addon target)")
    return found[0]


def make_chroot(suite):
    """The chroot of `suite` (trixie, sid) with its Blender, made once by scripts/blender-chroots.sh
    and reused; RuntimeError with a message where it cannot be made (root and network once)."""
    done = subprocess.run(["bash", str(ROOT / "scripts" / "blender-chroots.sh"), suite], capture_output=True,
                          text=True)
    sys.stderr.write(done.stderr)
    if done.returncode != 0:
        raise RuntimeError(f"the {suite} chroot could not be made (see above); it needs root and network once. "
                           "DWV_TEST_QUICK=1 scripts/test.sh leaves these tests out")
    chroot = Path(done.stdout.split()[1])
    if not (chroot / "usr" / "bin" / "blender").is_file():
        raise RuntimeError(f"no Blender at {chroot}/usr/bin/blender (scripts/blender-chroots.sh {suite} should "
                           "have installed it)")
    return chroot


def blender_command(command, env, chroot=None):
    """`command` (its paths as the process sees them) with only `env`, inside `chroot` if given.
    As root it runs in a mount namespace of its own (unshare --mount --propagation private):
    /proc is mounted there for a chroot, and every mount the process makes goes away with it, on
    failure too."""
    environment = ["env", "-i"] + [f"{k}={v}" for k, v in env.items()]
    if chroot is not None:
        script = 'mount -t proc proc "$1/proc" && shift && exec chroot "$@"'
        return ["unshare", "--mount", "--propagation", "private", "sh", "-c", script, "sh", str(chroot),
                str(chroot), *environment, *command]
    if os.geteuid() == 0:
        return ["unshare", "--mount", "--propagation", "private", *environment, *command]
    return environment + command


def scratch_dependencies(library, deps):
    """Copies the host's copies of the library's dependencies other than the base ones into
    `deps`; returns their names (empty for a self-contained library)."""
    info, problem = libcheck.read_elf(str(library))
    if problem is not None or info is None:
        fail(f"cannot read {library}: {problem}")
    extra = [name for name in info.needed if name not in BASE_LIBRARIES]
    if not extra:
        return []
    listing = subprocess.run(["ldd", str(library)], capture_output=True, text=True).stdout
    resolved = dict(re.findall(r"^\s*(\S+) => (/\S+)", listing, re.M))
    deps.mkdir(parents=True, exist_ok=True)
    copied = []
    for name, path in sorted(resolved.items()):
        if name in BASE_LIBRARIES:
            continue
        shutil.copy2(path, deps / name)  # follows links: the file itself, under its SONAME
        copied.append(name)
    return copied


def crash_reports(folders):
    found = set()
    for folder in folders:
        if folder.is_dir():
            found.update(str(p) for p in folder.glob("*.crash.txt"))
    return found


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blender", required=True, help="host, trixie or sid")
    parser.add_argument("--build-dir", required=True, type=Path)
    parser.add_argument("--script", default="test_package.py", choices=SCRIPTS)
    parser.add_argument("--work", type=Path,
                        help="folder for the results (default BUILD/tests/package-NAME, fidelity-NAME, ui-NAME...)")
    parser.add_argument("--cc", default=os.environ.get("CC", "cc"))
    parser.add_argument("--clang", default="clang-14" if shutil.which("clang-14") else "clang")
    parser.add_argument("--host-blender", default=shutil.which("blender") or "blender")
    parser.add_argument("--timeout", type=float, default=900.0)
    parser.add_argument("--ui", action="store_true",
                        help="run test_ui.py in Blender's UI under Xvfb instead of test_package.py headless")
    parser.add_argument("--keep-going", action="store_true",
                        help="run every step even after one failed (diagnosis; later steps build on earlier ones)")
    parser.add_argument("--keep-scratch", action="store_true",
                        help="keep the scratch folder (the test's images) after a pass too (diagnosis)")
    args = parser.parse_args(argv)
    build = args.build_dir.resolve()
    legacy, extension, library = build / "dwivedi_bake.zip", extension_zip(build), build / "libdwivedi.so.1"
    for path in (legacy, library):
        if not path.is_file():
            fail(f"{path} is missing (build first)")
    test_script = "test_ui.py" if args.ui else args.script
    package = test_script == "test_package.py"
    kind = "package" if package else Path(test_script).stem.replace("test_", "", 1)
    work = (args.work or build / "tests" / f"{kind}-{args.blender}").resolve()
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    root = os.geteuid() == 0
    total = time.monotonic()

    if args.blender == "host":
        chroot = None
        stage = work / "stage"
    elif args.blender in ("trixie", "sid"):
        if not root:
            fail(f"the {args.blender} chroot test needs root (chroot, mounts); DWV_TEST_QUICK=1 leaves it out")
        try:
            chroot = step("chroot", make_chroot, args.blender)
        except RuntimeError as error:
            fail(str(error))
        stage = chroot / "tmp" / f"dwivedi-{kind}-{args.blender}-{os.getpid()}"
        if stage.exists():
            shutil.rmtree(stage)
    else:
        fail(f"--blender {args.blender}: host, trixie or sid")

    def inside(path):
        """`path` as the Blender process sees it."""
        return "/" + str(Path(path).relative_to(chroot)) if chroot is not None else str(path)

    def stage_files():
        (stage / "scripts").mkdir(parents=True)
        for name in sorted({test_script, "harness.py", "scenes.py", "uv_bakes.py"}):
            shutil.copy2(HERE / name, stage / "scripts" / name)
        shutil.copy2(legacy, stage / legacy.name)
        shutil.copy2(extension, stage / extension.name)
        fixtures = stage / "fixtures"
        if not package:  # the bad library files are test_package.py's
            fixtures.mkdir()
        else:
            subprocess.run([sys.executable, str(HERE / "fixtures.py"), "--library", str(library), "--out",
                            str(fixtures), "--cc", args.cc, "--clang", args.clang], check=False)
            if not (fixtures / "needs" / "libdwivedi.so.1").is_file():
                fail("tests/blender/fixtures.py could not build the fixtures (see above)")
        # The library the package carries (the self-contained build once there is one), not
        # necessarily build/libdwivedi.so.1: its dependencies decide the scratch set-up.
        import zipfile
        packaged = stage / "packaged-libdwivedi.so.1"
        with zipfile.ZipFile(extension) as zf:
            packaged.write_bytes(zf.read("dwivedi/libdwivedi.so.1"))
        packaged.chmod(0o755)
        return scratch_dependencies(packaged, stage / "deps") if chroot is not None else []

    copied = step("stage", stage_files)
    home = stage / "home"
    tmp = stage / "tmp"
    for d in (home, tmp):
        d.mkdir(parents=True, exist_ok=True)
    times_file = stage / "times.json"
    env = {
        "HOME": inside(home), "PATH": "/usr/local/bin:/usr/bin:/bin", "LANG": "C.UTF-8", "TMPDIR": inside(tmp),
        "BLENDER_USER_SCRIPTS": inside(home / "scripts"), "BLENDER_USER_CONFIG": inside(home / "config"),
        "BLENDER_USER_DATAFILES": inside(home / "datafiles"), "BLENDER_USER_EXTENSIONS": inside(home / "extensions"),
        "DWIVEDI_TEST_HOME": inside(home), "DWIVEDI_ADDON_ZIP": inside(stage / legacy.name),
        "DWIVEDI_EXTENSION_ZIP": inside(stage / extension.name), "DWIVEDI_FIXTURES": inside(stage / "fixtures"),
        "DWIVEDI_TEST_TIMES": inside(times_file), "PYTHONDONTWRITEBYTECODE": "1", "PYTHONUNBUFFERED": "1",
    }
    env.update({name: os.environ[name] for name in FIDELITY_SETTINGS if name in os.environ})
    if copied:
        env["DWIVEDI_TEST_PRELOAD"] = inside(stage / "deps")
        print(f"run_package_tests: SCRATCH SET-UP: the bundled library is not self-contained (it links "
              f"{', '.join(copied)}); copies of the host's are in {stage / 'deps'} and preloaded by the test, "
              "never in a package")
    if root:
        env["DWIVEDI_PRIVATE_MOUNTS"] = "1"
    if args.ui and os.environ.get("DWIVEDI_UI_SCREENSHOT"):
        env["DWIVEDI_UI_SCREENSHOT"] = inside(stage / "screenshot.png")  # copied to WORK at the end
    if args.ui and os.environ.get("DWIVEDI_UI_ONLY"):
        env["DWIVEDI_UI_ONLY"] = os.environ["DWIVEDI_UI_ONLY"]
    if args.keep_going:
        env["DWIVEDI_TEST_KEEP_GOING"] = "1"
    blender = "/usr/bin/blender" if chroot is not None else args.host_blender
    if args.ui:
        # A display number of its own per Blender (Xvfb's abstract socket is shared by the host
        # and the chroots, which do not see each other's lock files); -a moves on from it if taken.
        display = {"host": 90, "trixie": 100, "sid": 110}[args.blender]
        command = ["xvfb-run", "-a", "-n", str(display), "-s", "-screen 0 1280x800x24 -nolisten tcp", blender,
                   "--factory-startup", "--enable-event-simulate", "--python", inside(stage / "scripts" / test_script)]
    else:
        command = [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                   inside(stage / "scripts" / test_script)]
    full = blender_command(command, env, chroot)
    watched = [tmp, Path("/tmp")] + ([chroot / "tmp"] if chroot is not None else [])
    before = crash_reports(watched)
    print("run_package_tests: " + " ".join(full[-len(command):]), flush=True)
    start = time.monotonic()
    try:
        done = subprocess.run(full, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              timeout=args.timeout)
        output, code = done.stdout, done.returncode
    except subprocess.TimeoutExpired as expired:
        output = (expired.stdout or b"").decode("utf-8", "replace") if isinstance(expired.stdout, bytes) else (
            expired.stdout or "")
        code = "timeout"
    TIMES["blender"] = round(time.monotonic() - start, 1)
    sys.stdout.write(output)
    new_crashes = sorted(crash_reports(watched) - before)
    steps = {}
    passed = None
    if times_file.is_file():
        data = json.loads(times_file.read_text())
        steps = data.get("seconds", {})
        passed = data.get("passed")
        TIMES["blender version"] = data.get("blender")
    TIMES["steps in Blender"] = steps
    TIMES["total"] = round(time.monotonic() - total, 1)
    (work / "times.json").write_text(json.dumps(TIMES, indent=1))
    for figures in home.glob("*_figures.json"):
        shutil.copy2(figures, work / figures.name)
    print(f"run_package_tests: {args.blender} {test_script}: times (s): {json.dumps(TIMES)}")
    problems = []
    if args.ui and passed is not True:
        problems.append("test_ui.py did not pass (see its output above)")
    if code != 0:
        problems.append(f"Blender exited with {code}" + (" (a crash: a signal)" if isinstance(code, int) and code < 0
                                                         else ""))
    if new_crashes:
        problems.append("crash reports written: " + ", ".join(new_crashes))
        for report in new_crashes:
            sys.stdout.write(Path(report).read_text(errors="replace")[:4000])
    if "Segmentation fault" in output or "Writing: " in output and ".crash.txt" in output:
        problems.append("Blender reported a crash")
    if problems:
        print(f"run_package_tests: {args.blender} {test_script}: FAILED: {'; '.join(problems)} "
              f"(scratch folder kept: {stage})", file=sys.stderr)
        return 1
    if (stage / "screenshot.png").is_file():
        shutil.copy2(stage / "screenshot.png", work / "screenshot.png")
    if args.keep_scratch:
        print(f"run_package_tests: scratch folder kept: {stage}")
    else:
        shutil.rmtree(stage)
    print(f"run_package_tests: {args.blender} {test_script}: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
