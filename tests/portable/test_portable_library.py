#!/usr/bin/env python3
"""The portable libdwivedi.so.1 (cmake/portable.cmake, issue 16) against a hostile host process.

    python3 tests/portable/test_portable_library.py --portable build/portable/libdwivedi.so.1 \
        --normal build/libdwivedi.so.1 --planted build/tests/libdwv_planted_symbols.so \
        --source-dir . [--bench-samples 64]

Checks, each failing with a message and a non-zero exit:
1. ELF: the portable library's NEEDED entries are only libc, libm, libstdc++, libgcc_s (and
   ld-linux, libpthread, libdl, librt); its SONAME is libdwivedi.so.1; every symbol it defines
   dynamically is dwv_*; every symbol it leaves undefined carries a glibc / libstdc++ / libgcc
   version (so none can bind to a host's Embree, OpenEXR, OpenColorIO, libpng, zlib...); no
   DF_STATIC_TLS (it must dlopen into any process).
2. A clean process bakes three scenes (an OBJ mesh, a PLY mesh, the default scene) with the
   normal library and writes EXR and PNG files: the reference.
3. A hostile process first loads, with RTLD_GLOBAL, a planted library defining exr_start_write,
   rtcNewDevice, png_create_write_struct, deflate, cJSON_*, ai*, OpenColorIO and yaml-cpp names
   that abort(), then Debian 12's own libembree3, libOpenEXRCore-3_1, libOpenColorIO 2.1, libtbb,
   libpng16, libz, libyaml-cpp, libexpat, libassimp, libcjson; then the portable library bakes
   the same scenes: pixels (RGBA, variance, samples), the EXR (every header attribute but the two
   wall-clock ones, dwivedi:seconds and dwivedi:error_vs_time, and every chunk) and the PNG file
   must be bit-identical to the reference. Then the reverse: the host's own symbols (looked up in the global scope and
   called) still resolve to the host's libraries, and none of them is found in ours.
4. The control: the normal library in that same hostile process must die in a planted symbol;
   if it does not, the harness proves nothing, and the test fails saying so.
With --bench-samples N it also times a larger bake (N samples per pixel) with both libraries in
clean processes of the same run, alternating, and prints seconds per sample.
Standard library only; any python3.
"""

import argparse
import ctypes
import ctypes.util
import hashlib
import json
import os
import re
import struct
import subprocess
import sys
import zlib
import tempfile
import time
from pathlib import Path

ALLOWED_NEEDED = re.compile(r"^(libc\.so\.6|libm\.so\.6|libstdc\+\+\.so\.6|libgcc_s\.so\.1|"
                            r"ld-linux-x86-64\.so\.2|ld-linux-aarch64\.so\.1|libpthread\.so\.0|"
                            r"libdl\.so\.2|librt\.so\.1)$")
ALLOWED_UNDEFINED_VERSION = re.compile(r"^(GLIBC_|GLIBCXX_|CXXABI_|GCC_)")
# Weak undefined references that toolchains leave in every shared library.
ALLOWED_UNVERSIONED_WEAK = {"__gmon_start__", "_ITM_deregisterTMCloneTable", "_ITM_registerTMCloneTable",
                            "__cxa_finalize"}

# Debian 12's own shared libraries of the same dependencies (sonames), loaded as a host would.
HOST_LIBRARIES = ["libembree3.so.3", "libOpenEXRCore-3_1.so.30", "libOpenColorIO.so.2.1", "libtbb.so.12",
                  "libpng16.so.16", "libz.so.1", "libyaml-cpp.so.0.7", "libexpat.so.1", "libassimp.so.5",
                  "libcjson.so.1"]
# (library, symbol not planted, how to call it and what it must give) for the reverse check.
HOST_CALLS = [("libz.so.1", "zlibVersion", ctypes.c_char_p, b"1.2."),
              ("libpng16.so.16", "png_get_libpng_ver", ctypes.c_char_p, b"1.6."),
              ("libOpenEXRCore-3_1.so.30", "exr_get_library_version", None, None),
              ("libembree3.so.3", "rtcGetDeviceError", None, None),
              ("libcjson.so.1", "cJSON_Version", ctypes.c_char_p, b"1.7."),
              ("libexpat.so.1", "XML_ExpatVersion", ctypes.c_char_p, b"expat_2."),
              ("libassimp.so.5", "aiGetVersionMajor", ctypes.c_uint, None)]

SCENES = [("backlit_slab.json", {"width": 40, "height": 24, "samples": 6}),
          ("frontlit_sphere.json", {"width": 32, "height": 32, "samples": 6}),
          (None, {"width": 40, "height": 24, "samples": 4})]


def fail(message):
    print(f"test_portable_library: FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def readelf(*args):
    try:
        return subprocess.run(["readelf", "-W", *args], check=True, capture_output=True, text=True).stdout
    except FileNotFoundError:
        fail("readelf is missing (apt-get install binutils)")
    except subprocess.CalledProcessError as error:
        fail(f"readelf {' '.join(args)} failed: {error.stderr.strip()}")


def same_embree_isa():
    """Whether Debian's Embree (SSE2, SSE4.2, AVX, AVX2, AVX-512 kernels) and the portable one
    (SSE2, AVX2, AVX-512: scripts/build-portable-deps.sh) pick the same kernels on this CPU:
    results differ in the last bits between Embree's ISAs, so bit-identity is expected only then."""
    try:
        flags = set()
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("flags"):
                flags.update(line.split(":", 1)[1].split())
    except OSError:
        return True
    return {"avx2", "fma", "bmi1", "bmi2", "lzcnt" if "lzcnt" in flags else "abm"} <= flags


def check_elf(path):
    dynamic = readelf("-d", str(path))
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", dynamic)
    bad = [n for n in needed if not ALLOWED_NEEDED.match(n)]
    if bad:
        fail(f"{path} needs {bad} (only libc, libm, libstdc++, libgcc_s and the loader are allowed)")
    soname = re.findall(r"\(SONAME\)\s+Library soname: \[([^\]]+)\]", dynamic)
    if soname != ["libdwivedi.so.1"]:
        fail(f"{path}: SONAME {soname}, expected libdwivedi.so.1")
    flags = " ".join(re.findall(r"\(FLAGS\)\s+(.*)", dynamic))
    if "STATIC_TLS" in flags:
        fail(f"{path} has DF_STATIC_TLS ({flags}): initial-exec TLS cannot be relied on in a dlopen()ed library")
    defined, undefined = [], []
    definitions = readelf("-V", str(path)).split("Version definition section", 1)[-1].split("Version needs section")[0]
    version_nodes = set(re.findall(r"Name: (\S+)", definitions))
    if "DWIVEDI_1" not in version_nodes:
        fail(f"{path} defines no symbol version DWIVEDI_1 (versions: {sorted(version_nodes)}): not linked with src/dwivedi.map?")
    for line in readelf("--dyn-syms", str(path)).splitlines():
        fields = line.split()
        if len(fields) < 8 or not fields[0].rstrip(":").isdigit():
            continue
        bind, ndx, name = fields[4], fields[6], fields[7]
        if not name or fields[3] == "SECTION" or fields[3] == "FILE":
            continue
        base, _, version = name.partition("@")
        version = version.lstrip("@")
        if ndx == "ABS" and (base == version or base in version_nodes):
            continue  # the version node itself (DWIVEDI_1), from src/dwivedi.map
        if ndx == "UND":
            undefined.append((base, version, bind))
        elif bind in ("GLOBAL", "WEAK", "UNIQUE") and fields[5] != "HIDDEN":
            defined.append((base, version))
    exported = [b for b, _ in defined]
    foreign = [b for b in exported if not b.startswith("dwv_")]
    if foreign:
        fail(f"{path} exports {len(foreign)} symbols that are not dwv_*, e.g. {foreign[:8]}")
    if len(exported) < 10:
        fail(f"{path} exports only {len(exported)} dwv_* symbols: is it the library?")
    loose = [f"{b}@{v}" if v else b for b, v, bind in undefined
             if not (ALLOWED_UNDEFINED_VERSION.match(v) or (not v and bind == "WEAK" and b in ALLOWED_UNVERSIONED_WEAK))]
    if loose:
        fail(f"{path} leaves {len(loose)} symbols to the host's libraries, e.g. {loose[:8]}")
    print(f"ELF: NEEDED {needed}; exports {len(exported)} symbols, all dwv_*; "
          f"{len(undefined)} undefined, all versioned glibc/libstdc++/libgcc; size {path.stat().st_size} bytes")


# ---- the worker (runs in a child process) -------------------------------------------------------

# EXR attributes that hold wall-clock time (differ between any two bakes): left out of the digest.
EXR_TIMING_ATTRIBUTES = {b"dwivedi:seconds", b"dwivedi:error_vs_time"}


def exr_digest(path):
    """SHA-256 of an EXR file's header attributes (but the timing ones) and of its chunks (from the
    first chunk to the end; the offset table is left out, as it moves with the header's length)."""
    data = path.read_bytes()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path} is not an OpenEXR file")
    pos, attributes = 8, []
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end]
        pos = end + 1
        if not name:
            break
        end = data.index(b"\0", pos)
        kind = data[pos:end]
        size = struct.unpack_from("<i", data, end + 1)[0]
        value = data[end + 5:end + 5 + size]
        pos = end + 5 + size
        if name not in EXR_TIMING_ATTRIBUTES:
            attributes.append(name + b"\0" + kind + b"\0" + value)
    first_chunk = struct.unpack_from("<Q", data, pos)[0]
    if not pos < first_chunk < len(data):
        raise ValueError(f"{path}: first chunk offset {first_chunk} out of range")
    digest = hashlib.sha256()
    for attribute in sorted(attributes):
        digest.update(struct.pack("<Q", len(attribute)) + attribute)
    digest.update(data[first_chunk:])
    return digest.hexdigest()


def png_pixels(path):
    """The 8-bit samples of a non-interlaced PNG (colour types 2 and 6), unfiltered; stdlib only."""
    data = path.read_bytes()
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack_from(">I4s", data, pos)
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f"{path}: PNG depth {depth} colour {colour} interlace {interlace} not handled")
    bpp = 3 if colour == 2 else 4
    raw, stride, out, previous = zlib.decompress(idat), width * bpp, bytearray(), bytearray(width * bpp)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = previous[i], previous[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out += line
        previous = line
    return bytes(out)


def dladdr_file(address):
    class DlInfo(ctypes.Structure):
        _fields_ = [("dli_fname", ctypes.c_char_p), ("dli_fbase", ctypes.c_void_p),
                    ("dli_sname", ctypes.c_char_p), ("dli_saddr", ctypes.c_void_p)]
    libc = ctypes.CDLL(None)
    libc.dladdr.argtypes = [ctypes.c_void_p, ctypes.POINTER(DlInfo)]
    info = DlInfo()
    if not libc.dladdr(ctypes.c_void_p(address), ctypes.byref(info)) or not info.dli_fname:
        return None
    return os.path.realpath(info.dli_fname.decode())


def worker(args):
    handles = {}
    if args.hostile:
        ctypes.CDLL(args.planted, mode=ctypes.RTLD_GLOBAL)
        for name in HOST_LIBRARIES:
            try:
                handles[name] = ctypes.CDLL(name, mode=ctypes.RTLD_GLOBAL)
            except OSError as error:
                print(f"worker: cannot load the host library {name}: {error}", file=sys.stderr)
                return 3
    sys.path.insert(0, str(Path(args.source_dir) / "python_shim"))
    import dwivedi  # noqa: E402
    library = dwivedi.use_library(args.library)
    out = Path(args.out)
    results = {"library": library, "scenes": []}
    scene_dir = Path(args.source_dir) / "examples" / "scenes"
    scenes = SCENES if not args.bench_samples else [(None, {"width": 96, "height": 64, "samples": args.bench_samples})]
    for index, (name, overrides) in enumerate(scenes):
        scene = dwivedi.Scene.load(scene_dir / name) if name else dwivedi.Scene.default()
        with scene:
            start = time.perf_counter()
            image = dwivedi.bake(scene, seed=7, threads=2, **overrides)
            seconds = time.perf_counter() - start
            exr, png = out / f"scene{index}.exr", out / f"scene{index}.png"
            image.write_exr(exr)
            image.write_png(png)
            digest = hashlib.sha256()
            for view in (image.rgba, image.variance, image.samples):
                digest.update(view.cast("B"))
            stats = image.stats
            results["scenes"].append({
                "scene": name or "default", "pixels_sha256": digest.hexdigest(),
                "exr_sha256": exr_digest(exr),
                "png_sha256": hashlib.sha256(png.read_bytes()).hexdigest(), "png_file": str(png),
                "mean_rgb": list(stats.mean_rgb), "samples": stats.samples_per_pixel,
                "seconds": seconds, "width": image.width, "height": image.height})
            image.close()
    if args.hostile:
        # The reverse: after ours is loaded and used, the host's symbols still come from the host.
        ours = os.path.realpath(library)
        ours_handle = ctypes.CDLL(library)
        everyone = ctypes.CDLL(None)
        for lib_name, symbol, restype, expect in HOST_CALLS:
            host_path = None
            function = getattr(everyone, symbol)
            address = ctypes.cast(function, ctypes.c_void_p).value
            host_address = ctypes.cast(getattr(handles[lib_name], symbol), ctypes.c_void_p).value
            where = dladdr_file(address)
            if address != host_address or where == ours:
                print(f"worker: {symbol} in the global scope is at {where}, not in the host's {lib_name}", file=sys.stderr)
                return 4
            if restype is not None:
                function.restype = restype
                value = function()
                if expect is not None and not (isinstance(value, bytes) and value.startswith(expect)):
                    print(f"worker: the host's {symbol}() gave {value!r}, expected {expect!r}...", file=sys.stderr)
                    return 4
            if hasattr(ours_handle, symbol):
                host_path = dladdr_file(ctypes.cast(getattr(ours_handle, symbol), ctypes.c_void_p).value)
                if host_path == ours:
                    print(f"worker: {symbol} is found in the portable library {ours}", file=sys.stderr)
                    return 4
        # Names the planted library holds: looked up through our library, none is ours.
        for symbol in ("exr_start_write", "rtcNewDevice", "png_create_write_struct", "deflate",
                       "_ZN16OpenColorIO_v2_16Config16CreateFromStreamERSi", "_ZN4YAML4LoadERSi"):
            if hasattr(ours_handle, symbol):
                where = dladdr_file(ctypes.cast(getattr(ours_handle, symbol), ctypes.c_void_p).value)
                if where == ours:
                    print(f"worker: {symbol} is exported by the portable library", file=sys.stderr)
                    return 4
        results["reverse_checked"] = [s for _, s, _, _ in HOST_CALLS]
    (out / "results.json").write_text(json.dumps(results, indent=1))
    return 0


def run_worker(script, args, library, hostile, out, bench_samples=0):
    command = [sys.executable, str(script), "--worker", "--library", str(library), "--planted", str(args.planted),
               "--source-dir", str(args.source_dir), "--out", str(out), "--bench-samples", str(bench_samples)]
    if hostile:
        command.append("--hostile")
    env = dict(os.environ)
    env.pop("DWIVEDI_LIBRARY", None)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    completed = subprocess.run(command, capture_output=True, text=True, env=env, timeout=1800)
    return completed


def load_results(out):
    return json.loads((Path(out) / "results.json").read_text())


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--portable", type=Path)
    parser.add_argument("--normal", type=Path)
    parser.add_argument("--planted", type=Path, required=True)
    parser.add_argument("--source-dir", type=Path, required=True)
    parser.add_argument("--bench-samples", type=int, default=0)
    parser.add_argument("--bench-rounds", type=int, default=3)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--hostile", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--library", help=argparse.SUPPRESS)
    parser.add_argument("--out", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        sys.exit(worker(args))
    for name in ("portable", "normal", "planted"):
        path = getattr(args, name)
        if path is None or not path.is_file():
            fail(f"--{name} {path} is not a file (build it first)")
    script = Path(__file__).resolve()

    check_elf(args.portable)
    with tempfile.TemporaryDirectory(prefix="dwv-portable-") as tmp:
        outs = {k: Path(tmp) / k for k in ("normal", "portable", "control")}
        for p in outs.values():
            p.mkdir()
        normal = run_worker(script, args, args.normal, False, outs["normal"])
        if normal.returncode != 0:
            fail(f"the normal library's bake in a clean process failed (exit {normal.returncode}):\n{normal.stderr}")
        portable = run_worker(script, args, args.portable, True, outs["portable"])
        if portable.returncode != 0:
            fail(f"the portable library in the hostile process failed (exit {portable.returncode}):\n{portable.stderr}")
        control = run_worker(script, args, args.normal, True, outs["control"])
        if control.returncode == 0 or "planted_symbols:" not in control.stderr:
            fail("control: the normal library in the hostile process did not die in a planted symbol "
                 f"(exit {control.returncode}); the harness would not catch interposition:\n{control.stderr}")
        planted_hit = re.search(r"planted_symbols: (\S+) was called", control.stderr).group(1)
        print(f"control: the normal library in the hostile process died in the planted {planted_hit} "
              f"(exit {control.returncode}), as it must")
        reference, ours = load_results(outs["normal"]), load_results(outs["portable"])
        # The PNG goes through OpenColorIO's display transform: the portable build has OCIO 2.1.3
        # where Debian 12 has 2.1.2 (the archive lacks 2.1.2's source here), so the PNG is
        # compared by its 8-bit values, each within 1, and the differing ones are counted.
        exact_keys = ("pixels_sha256", "exr_sha256", "samples", "width", "height")
        if not same_embree_isa():
            # Embree's kernels for SSE4.2 and AVX (Debian's build has them, the portable one goes
            # from SSE2 to AVX2) round hit distances differently in the last bits.
            exact_keys = ("samples", "width", "height")
            print("note: this CPU has no AVX2, so Debian's Embree runs its SSE4.2 or AVX kernels, which the portable "
                  "build does not have: images are compared to 1e-6 relative, not bit for bit")
        for ref, got in zip(reference["scenes"], ours["scenes"]):
            if "pixels_sha256" not in exact_keys:
                for a, b in zip(ref["mean_rgb"], got["mean_rgb"]):
                    if abs(a - b) > 1e-6 * max(abs(a), abs(b), 1e-30):
                        fail(f"scene {ref['scene']}: mean {ref['mean_rgb']} (normal) and {got['mean_rgb']} (portable) differ")
            for key in exact_keys:
                if ref[key] != got[key]:
                    fail(f"scene {ref['scene']}: {key} differs between the normal library ({ref[key]}) and the "
                         f"portable one in the hostile process ({got[key]})")
            png_ref, png_got = png_pixels(Path(ref["png_file"])), png_pixels(Path(got["png_file"]))
            if len(png_ref) != len(png_got):
                fail(f"scene {ref['scene']}: the PNGs have different sizes")
            worst = max((abs(x - y) for x, y in zip(png_ref, png_got)), default=0)
            differing = sum(1 for x, y in zip(png_ref, png_got) if x != y)
            if worst > 1 or differing > max(1, len(png_ref) // 1000):
                fail(f"scene {ref['scene']}: PNG values differ by up to {worst} in {differing} of {len(png_ref)} "
                     "samples between the normal and the portable library (allowed: 1, in at most 0.1%)")
            ref["png_note"] = ("identical" if ref["png_sha256"] == got["png_sha256"]
                               else f"{differing} of {len(png_ref)} 8-bit values differ by 1")
            if ref["samples"] <= 0 or max(ref["mean_rgb"]) <= 0.0:
                fail(f"scene {ref['scene']}: the reference bake is empty ({ref['samples']} samples, mean {ref['mean_rgb']})")
            print(f"scene {ref['scene']}: {ref['width']}x{ref['height']}, {ref['samples']} spp: pixels and EXR "
                  f"bit-identical (pixels sha256 {ref['pixels_sha256'][:16]}), PNG {ref['png_note']}; {ref['seconds']:.3f} s normal, "
                  f"{got['seconds']:.3f} s portable (hostile process)")
        if len(ours["scenes"]) != len(SCENES) or len(reference["scenes"]) != len(SCENES):
            fail("not every scene was baked")
        print(f"reverse: {', '.join(ours['reverse_checked'])} resolve to the host's libraries after ours was loaded")

        if args.bench_samples:
            times = {"normal": [], "portable": []}
            spp = None
            for round_index in range(args.bench_rounds):
                for kind, library in (("normal", args.normal), ("portable", args.portable)):
                    out = Path(tmp) / f"bench-{kind}-{round_index}"
                    out.mkdir()
                    done = run_worker(script, args, library, False, out, args.bench_samples)
                    if done.returncode != 0:
                        fail(f"bench with the {kind} library failed:\n{done.stderr}")
                    scene = load_results(out)["scenes"][0]
                    spp = scene["samples"]
                    times[kind].append(scene["seconds"] / scene["samples"])
            best = {k: min(v) for k, v in times.items()}
            print(f"bench: default scene 96x64, {spp} spp, 2 threads, {args.bench_rounds} rounds alternating: "
                  f"seconds per sample (best) normal {best['normal'] * 1e3:.2f} ms, portable {best['portable'] * 1e3:.2f} ms, "
                  f"ratio portable/normal {best['portable'] / best['normal']:.3f}; all rounds: "
                  + "; ".join(f"{k} " + ", ".join(f"{t * 1e3:.2f}" for t in v) for k, v in times.items()))
    print("test_portable_library: OK")


if __name__ == "__main__":
    main()
