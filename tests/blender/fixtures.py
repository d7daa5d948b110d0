#!/usr/bin/env python3
"""Builds the bad library files the package tests put where the add-on looks for libdwivedi:

    python3 tests/blender/fixtures.py --library build/libdwivedi.so.1 --out DIR [--cc cc] [--clang clang]

DIR/<case>/libdwivedi.so.1 for each case, all real files a user could end up with:
  aarch64     a shared library built for aarch64 (clang --target=aarch64-linux-gnu, ld.lld)
  i386        one built for 32-bit x86 (clang --target=i386-linux-gnu, ld.lld): same CPU family,
              another word size
  truncated   the first third of the real library (an interrupted copy or download)
  garbage     a text file named libdwivedi.so.1
  abi0        a shared library with SONAME libdwivedi.so.0 (an older ABI generation)
  abi2        a shared library with SONAME libdwivedi.so.2 (a newer one)
  old         SONAME libdwivedi.so.1 but only the version functions (a library older than the shim)
  needs       SONAME libdwivedi.so.1, every function the shim declares, and a dependency
              (libdwivedi_test_missing.so.7) that is not there: only the loader can tell
The host-CPU ones are built with the C compiler (--cc) and depend on libc alone, so they load
the same way in a chroot. Exit status 1 with a message if a compiler is missing.
"""
import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CASES = ("aarch64", "i386", "truncated", "garbage", "abi0", "abi2", "old", "needs")


def shim_functions():
    sys.path.insert(0, str(ROOT / "python_shim"))
    import dwivedi  # loads no library
    return dwivedi.LIBRARY_FUNCTIONS


def run(command):
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"fixtures: {' '.join(command)} failed:\n{done.stderr}")


def build(library: Path, out: Path, cc: str, clang: str) -> None:
    for tool in (cc, clang):
        if shutil.which(tool) is None:
            raise SystemExit(f"fixtures: no compiler '{tool}' (the aarch64 library needs clang and ld.lld: "
                             "apt-get install clang-14 lld-14)")
    out.mkdir(parents=True, exist_ok=True)
    for case in CASES:
        (out / case).mkdir(exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        version = work / "version.c"
        version.write_text("unsigned dwv_version(void) { return 100; }\n"
                           "const char *dwv_version_string(void) { return \"0.1.0\"; }\n")
        everything = work / "all.c"
        everything.write_text("".join(f"int {name}(void) {{ return 0; }}\n" for name in shim_functions()))
        dependency = work / "dependency.c"
        dependency.write_text("int dwivedi_test_missing(void) { return 7; }\n")
        uses = work / "uses.c"
        uses.write_text("int dwivedi_test_missing(void);\nint dwivedi_test_uses(void) { return dwivedi_test_missing(); }\n")

        def shared(sources, soname, target, extra=()):
            run([cc, "-shared", "-fPIC", "-o", str(target), *map(str, sources), f"-Wl,-soname,{soname}", *extra])

        shared([version], "libdwivedi.so.0", out / "abi0" / "libdwivedi.so.1")
        shared([version], "libdwivedi.so.2", out / "abi2" / "libdwivedi.so.1")
        shared([version], "libdwivedi.so.1", out / "old" / "libdwivedi.so.1")
        missing = work / "libdwivedi_test_missing.so.7"
        shared([dependency], missing.name, missing)
        shared([everything, uses], "libdwivedi.so.1", out / "needs" / "libdwivedi.so.1",
               [f"-L{work}", "-l:libdwivedi_test_missing.so.7"])
        # A real aarch64 shared object (no libc needed: nothing is ever run).
        run([clang, "--target=aarch64-linux-gnu", "-fPIC", "-nostdlib", "-shared", "-fuse-ld=lld",
             "-Wl,-soname,libdwivedi.so.1", "-o", str(out / "aarch64" / "libdwivedi.so.1"), str(version)])
        run([clang, "--target=i386-linux-gnu", "-fPIC", "-nostdlib", "-shared", "-fuse-ld=lld",
             "-Wl,-soname,libdwivedi.so.1", "-o", str(out / "i386" / "libdwivedi.so.1"), str(version)])
    data = library.resolve().read_bytes()
    (out / "truncated" / "libdwivedi.so.1").write_bytes(data[:len(data) // 3])
    (out / "garbage" / "libdwivedi.so.1").write_text("this is not a library\n")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, type=Path)
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--cc", default="cc")
    parser.add_argument("--clang", default="clang")
    args = parser.parse_args(argv)
    build(args.library, args.out, args.cc, args.clang)
    return 0


if __name__ == "__main__":
    sys.exit(main())
