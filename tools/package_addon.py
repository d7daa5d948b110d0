#!/usr/bin/env python3
"""Builds the installable Blender add-on zip: dwivedi_bake/ with the Python shim and the library.

    python3 tools/package_addon.py --library build/libdwivedi.so.1 --out build/dwivedi_bake.zip

The zip holds dwivedi_bake/ (blender_addon/dwivedi_bake), dwivedi_bake/dwivedi/ (python_shim/dwivedi)
and dwivedi_bake/dwivedi/libdwivedi.so.1 (the library file itself, symbolic links resolved), where
the shim looks first. It is written under a temporary name and renamed when complete. Install it
with Edit > Preferences > Add-ons > Install, or bpy.ops.preferences.addon_install(filepath=...).
"""
import argparse
import os
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _files(directory: Path):
    for path in sorted(directory.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts and path.suffix not in {".pyc", ".pyo"}:
            yield path


def build(library: Path, out: Path) -> None:
    addon = ROOT / "blender_addon" / "dwivedi_bake"
    shim = ROOT / "python_shim" / "dwivedi"
    if not (addon / "__init__.py").is_file():
        raise SystemExit(f"package_addon: no add-on at {addon}")
    if not (shim / "__init__.py").is_file():
        raise SystemExit(f"package_addon: no shim at {shim}")
    real = library.resolve()
    if not real.is_file():
        raise SystemExit(f"package_addon: the library {library} is not a file (build it first)")
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name(out.name + ".partial")
    # Fixed timestamps keep the zip identical from build to build when nothing changed.
    stamp = (2020, 1, 1, 0, 0, 0)

    def add(zf: zipfile.ZipFile, source: Path, name: str, mode: int = 0o644) -> None:
        info = zipfile.ZipInfo(name, stamp)
        info.external_attr = (0o100000 | mode) << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        zf.writestr(info, source.read_bytes())

    with zipfile.ZipFile(partial, "w") as zf:
        for path in _files(addon):
            add(zf, path, "dwivedi_bake/" + path.relative_to(addon).as_posix())
        for path in _files(shim):
            add(zf, path, "dwivedi_bake/dwivedi/" + path.relative_to(shim).as_posix())
        add(zf, real, "dwivedi_bake/dwivedi/libdwivedi.so.1", 0o755)
    os.replace(partial, out)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, type=Path, help="libdwivedi.so.1 to bundle")
    parser.add_argument("--out", required=True, type=Path, help="the zip to write")
    args = parser.parse_args(argv)
    build(args.library, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
