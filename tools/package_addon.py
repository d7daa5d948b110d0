#!/usr/bin/env python3
"""Builds the Blender packages of the add-on from one source, blender_addon/dwivedi_bake:

    python3 tools/package_addon.py --library build/libdwivedi.so.1 --out-dir build

writes
  build/dwivedi_bake.zip                          the legacy add-on for Blender 3.x (bl_info):
      dwivedi_bake/...  installed by Preferences > Add-ons > Install, or
      bpy.ops.preferences.addon_install(filepath=...) + addon_enable(module="dwivedi_bake");
  build/dwivedi_bake-<version>-linux-x64.zip      the extension for Blender 4.2+
      (blender_manifest.toml at the top): installed by Get Extensions > Install from Disk, or
      bpy.ops.extensions.package_install_files(filepath=..., repo="user_default"); its module is
      bl_ext.<repository>.dwivedi_bake.
Both hold the add-on's Python files, the shim (dwivedi/, python_shim/dwivedi) and the library
(dwivedi/libdwivedi.so.1, symbolic links resolved, debug sections and unneeded symbols stripped by
objcopy: 11 MB instead of 17 MB, its .dynsym exports untouched), where the add-on looks for it. Tools that are
not part of the shim (tools/cycles_report.py) are not in either. Each zip is written under a
temporary name in the same folder and renamed when complete, so a reader never sees half a zip.
Exit status 1 with a message if a source is missing or the manifest disagrees with bl_info.
(--out FILE, the old form, writes the legacy zip to FILE and the extension beside it.)
"""
import argparse
import ast
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ADDON = ROOT / "blender_addon" / "dwivedi_bake"
SHIM = ROOT / "python_shim" / "dwivedi"
MANIFEST = "blender_manifest.toml"
PLATFORM = "linux-x64"
# Fixed timestamps keep a zip identical from build to build when nothing changed.
STAMP = (2020, 1, 1, 0, 0, 0)


def fail(message: str) -> "SystemExit":
    return SystemExit(f"package_addon: {message}")


def _files(directory: Path):
    for path in sorted(directory.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts and path.suffix not in {".pyc", ".pyo"}:
            yield path


def bl_info_version() -> str:
    """bl_info["version"] of the add-on's __init__.py as "x.y.z", read without importing bpy."""
    tree = ast.parse((ADDON / "__init__.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "bl_info" for t in node.targets):
            info = ast.literal_eval(node.value)
            return ".".join(str(part) for part in info["version"])
    raise fail(f"no bl_info in {ADDON / '__init__.py'}")


def manifest_fields(text: str) -> dict:
    """The top-level `key = "value"` fields of a manifest (a TOML subset; enough to check ours)."""
    fields = {}
    for line in text.splitlines():
        if line.startswith("["):
            break
        found = re.match(r'^([a-z_]+)\s*=\s*"([^"]*)"\s*(#.*)?$', line)
        if found:
            fields[found.group(1)] = found.group(2)
    return fields


def check_sources(library: Path) -> str:
    """The add-on's version, after checking every source is there and the manifest agrees."""
    for what, path in (("add-on", ADDON / "__init__.py"), ("shim", SHIM / "__init__.py"),
                       ("manifest", ADDON / MANIFEST)):
        if not path.is_file():
            raise fail(f"no {what} at {path}")
    if not library.resolve().is_file():
        raise fail(f"the library {library} is not a file (build it first)")
    version = bl_info_version()
    fields = manifest_fields((ADDON / MANIFEST).read_text(encoding="utf-8"))
    for key in ("schema_version", "id", "version", "name", "tagline", "maintainer", "type", "blender_version_min"):
        if not fields.get(key):
            raise fail(f"{ADDON / MANIFEST} has no {key}")
    if fields["version"] != version:
        raise fail(f"{ADDON / MANIFEST} says version {fields['version']}, bl_info says {version}: make them agree")
    if fields["id"] != ADDON.name:
        raise fail(f"{ADDON / MANIFEST} has id {fields['id']}, the package folder is {ADDON.name}")
    return version


def _write(out: Path, entries) -> None:
    """Writes the zip `out` from (name in the zip, source file, mode) entries, atomically."""
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name(f".{out.name}.{os.getpid()}.partial")
    try:
        with zipfile.ZipFile(partial, "w") as zf:
            for name, source, mode in entries:
                info = zipfile.ZipInfo(name, STAMP)
                info.external_attr = (0o100000 | mode) << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                zf.writestr(info, source.read_bytes())
        os.replace(partial, out)
    except BaseException:
        partial.unlink(missing_ok=True)
        raise


def stripped_copy(library: Path, objcopy: str, directory: Path) -> Path:
    """A copy of `library` in `directory` without debug sections or symbols no relocation needs
    (`objcopy --strip-unneeded`: what Debian's dh_strip does to shared libraries); the dynamic
    symbol table, and so the exports, stay as they are."""
    tool = shutil.which(objcopy)
    if tool is None:
        raise fail(f"{objcopy} is not on PATH (binutils): it strips the packaged library")
    out = directory / library.name
    result = subprocess.run([tool, "--strip-unneeded", str(library.resolve()), str(out)],
                            capture_output=True, text=True, check=False)
    if result.returncode != 0 or not out.is_file():
        raise fail(f"{objcopy} could not strip {library}: {result.stderr.strip()}")
    return out


def entries(library: Path, prefix: str, with_manifest: bool):
    for path in _files(ADDON):
        relative = path.relative_to(ADDON).as_posix()
        if relative == MANIFEST and not with_manifest:
            continue
        yield prefix + relative, path, 0o644
    for path in _files(SHIM):
        yield prefix + "dwivedi/" + path.relative_to(SHIM).as_posix(), path, 0o644
    yield prefix + "dwivedi/libdwivedi.so.1", library.resolve(), 0o755


def extension_name(version: str) -> str:
    return f"{ADDON.name}-{version}-{PLATFORM}.zip"


def build(library: Path, legacy: Path, extension_dir: Path, objcopy: str = "objcopy") -> Path:
    """Writes both packages; returns the extension's path."""
    version = check_sources(library)
    with tempfile.TemporaryDirectory(prefix="package_addon.") as scratch:
        packaged = stripped_copy(library, objcopy, Path(scratch))
        _write(legacy, entries(packaged, ADDON.name + "/", with_manifest=False))
        extension = extension_dir / extension_name(version)
        _write(extension, entries(packaged, "", with_manifest=True))
    return extension


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, type=Path, help="libdwivedi.so.1 to bundle")
    where = parser.add_mutually_exclusive_group(required=True)
    where.add_argument("--out-dir", type=Path, help="the folder to write both packages into")
    where.add_argument("--out", type=Path, help="the legacy zip to write (the extension goes beside it)")
    parser.add_argument("--objcopy", default="objcopy", help="objcopy that strips the packaged library")
    parser.add_argument("--expect-version", help="fail unless the add-on's version is this (the build's)")
    parser.add_argument("--print-extension-name", action="store_true",
                        help="print the extension's file name and exit (writes nothing)")
    args = parser.parse_args(argv)
    if args.print_extension_name:
        print(extension_name(bl_info_version()))
        return 0
    if args.expect_version and args.expect_version != bl_info_version():
        raise fail(f"the add-on's bl_info version is {bl_info_version()}, the build's is {args.expect_version}: "
                   "make them agree")
    legacy = args.out if args.out is not None else args.out_dir / "dwivedi_bake.zip"
    extension = build(args.library, legacy, legacy.parent, args.objcopy)
    print(f"package_addon: wrote {legacy} (Blender 3.x) and {extension} (Blender 4.2+)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
