"""tools/package_addon.py and the add-on's library checks (blender_addon/dwivedi_bake/libcheck.py),
outside Blender: both packages from one source with the right layout and nothing else in them,
written atomically, refused when the manifest disagrees with bl_info; libcheck's verdict on the
real library and on each bad file tests/blender/fixtures.py builds. Standard library only.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest
import zipfile
from pathlib import Path

SOURCE_DIR = Path(os.environ.get("DWIVEDI_SOURCE_DIR", Path(__file__).resolve().parents[2]))
LIBRARY = Path(os.environ.get("DWIVEDI_LIBRARY", SOURCE_DIR / "build" / "libdwivedi.so.1"))
sys.path.append(str(SOURCE_DIR / "python_shim"))
sys.path.append(str(SOURCE_DIR / "blender_addon" / "dwivedi_bake"))

import dwivedi  # noqa: E402
import libcheck  # noqa: E402


def package(tree: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(tree / "tools" / "package_addon.py"), "--library", str(LIBRARY),
                           "--out-dir", str(out), *extra], capture_output=True, text=True, timeout=120)


class PackageTest(unittest.TestCase):
    def setUp(self) -> None:
        self.work = Path(tempfile.mkdtemp(prefix="dwivedi-package-test-"))

    def tearDown(self) -> None:
        shutil.rmtree(self.work)

    def test_both_packages(self) -> None:
        done = package(SOURCE_DIR, self.work, "--expect-version", dwivedi_version())
        self.assertEqual(done.returncode, 0, done.stderr)
        legacy = self.work / "dwivedi_bake.zip"
        extension = self.work / f"dwivedi_bake-{dwivedi_version()}-linux-x64.zip"
        self.assertEqual(sorted(p.name for p in self.work.iterdir()), sorted([legacy.name, extension.name]),
                         "nothing else (no partial file) is left")
        with zipfile.ZipFile(legacy) as zf:
            names = zf.namelist()
        self.assertTrue(all(n.startswith("dwivedi_bake/") for n in names), names)
        self.assertIn("dwivedi_bake/__init__.py", names)
        self.assertIn("dwivedi_bake/libcheck.py", names)
        self.assertIn("dwivedi_bake/LICENSE", names)
        self.assertIn("dwivedi_bake/dwivedi/libdwivedi.so.1", names)
        self.assertNotIn("dwivedi_bake/blender_manifest.toml", names)
        with zipfile.ZipFile(extension) as zf:
            ext_names = zf.namelist()
            manifest = zf.read("blender_manifest.toml").decode()
            library = zf.read("dwivedi/libdwivedi.so.1")
            mode = zf.getinfo("dwivedi/libdwivedi.so.1").external_attr >> 16
        self.assertIn("__init__.py", ext_names)
        self.assertIn("dwivedi/__init__.py", ext_names)
        self.assertIn("LICENSE", ext_names)
        self.assertEqual(mode & 0o777, 0o755)
        self.check_stripped_twin(library)
        for field in ('schema_version = "1.0.0"', 'id = "dwivedi_bake"', 'type = "add-on"',
                      'blender_version_min = "4.2.0"', 'platforms = ["linux-x64"]', "[permissions]", "files = "):
            self.assertIn(field, manifest)
        for names_ in (names, ext_names):
            self.assertFalse([n for n in names_ if "report" in n or n.endswith(".pyc") or "__pycache__" in n],
                             "the report tool and caches are not shipped")
        # Deterministic: the same sources give the same bytes.
        first = extension.read_bytes()
        self.assertEqual(package(SOURCE_DIR, self.work).returncode, 0)
        self.assertEqual(extension.read_bytes(), first)

    def check_stripped_twin(self, packaged: bytes) -> None:
        """The packaged library is the built one without debug sections and local symbols: smaller
        (when the build has any to strip), the same SONAME, NEEDED entries and exports, accepted by
        the add-on's own check, and it loads and answers through the shim."""
        built = LIBRARY.resolve()
        copy = self.work / "packaged" / "libdwivedi.so.1"
        copy.parent.mkdir()
        copy.write_bytes(packaged)
        sections = subprocess.run(["readelf", "-S", "-W", str(copy)], capture_output=True, text=True, check=True).stdout
        self.assertNotIn(".debug_info", sections)
        self.assertNotIn(".symtab", sections)
        if ".debug_info" in subprocess.run(["readelf", "-S", "-W", str(built)], capture_output=True, text=True,
                                           check=True).stdout:
            self.assertLess(len(packaged), built.stat().st_size)
        packaged_info, problem = libcheck.read_elf(str(copy))
        self.assertIsNone(problem)
        built_info, _ = libcheck.read_elf(str(built))
        self.assertEqual(packaged_info.soname, built_info.soname)
        self.assertEqual(packaged_info.needed, built_info.needed)
        self.assertIsNone(libcheck.check_file(str(copy), dwivedi.ABI_VERSION, dwivedi.LIBRARY_FUNCTIONS))

        def exports(path: Path) -> list:
            table = subprocess.run(["nm", "-D", "--defined-only", str(path)], capture_output=True, text=True,
                                   check=True).stdout
            return sorted(line.split()[-1] for line in table.splitlines() if line.strip())
        self.assertEqual(exports(copy), exports(built))
        probe = subprocess.run([sys.executable, "-c", "import dwivedi; print(dwivedi.version())"],
                               env={**os.environ, "DWIVEDI_LIBRARY": str(copy),
                                    "PYTHONPATH": str(SOURCE_DIR / "python_shim")},
                               capture_output=True, text=True, timeout=60)
        self.assertEqual(probe.returncode, 0, probe.stderr)
        self.assertEqual(probe.stdout.strip(), dwivedi_version())

    def test_objcopy_missing_is_an_error(self) -> None:
        done = package(SOURCE_DIR, self.work, "--objcopy", "dwivedi-no-such-objcopy")
        self.assertEqual(done.returncode, 1)
        self.assertIn("dwivedi-no-such-objcopy is not on PATH", done.stderr)
        self.assertEqual(list(self.work.iterdir()), [], "nothing written")

    def test_manifest_must_agree_with_bl_info(self) -> None:
        tree = self.work / "tree"
        for part in ("tools", "blender_addon", "python_shim"):
            shutil.copytree(SOURCE_DIR / part, tree / part, ignore=shutil.ignore_patterns("__pycache__"))
        manifest = tree / "blender_addon" / "dwivedi_bake" / "blender_manifest.toml"
        manifest.write_text(manifest.read_text().replace(f'version = "{dwivedi_version()}"', 'version = "9.9.9"'))
        out = self.work / "out"
        done = package(tree, out)
        self.assertEqual(done.returncode, 1)
        self.assertIn("says version 9.9.9, bl_info says", done.stderr)
        self.assertFalse(out.exists() and any(out.iterdir()), "nothing written")
        done = package(SOURCE_DIR, out, "--expect-version", "0.0.1")
        self.assertEqual(done.returncode, 1)
        self.assertIn("the build's is 0.0.1", done.stderr)


def dwivedi_version() -> str:
    import ast
    tree = ast.parse((SOURCE_DIR / "blender_addon" / "dwivedi_bake" / "__init__.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "bl_info":
            return ".".join(map(str, ast.literal_eval(node.value)["version"]))
    raise AssertionError("no bl_info")


class LibraryCheckTest(unittest.TestCase):
    """libcheck on the real library and on tests/blender/fixtures.py's bad files."""

    @classmethod
    def setUpClass(cls) -> None:
        cls.work = Path(tempfile.mkdtemp(prefix="dwivedi-libcheck-test-"))
        clang = shutil.which("clang-14") or shutil.which("clang") or "clang"
        done = subprocess.run([sys.executable, str(SOURCE_DIR / "tests" / "blender" / "fixtures.py"), "--library",
                               str(LIBRARY), "--out", str(cls.work), "--clang", clang,
                               "--cc", os.environ.get("CC", "cc")], capture_output=True, text=True, timeout=120)
        if done.returncode != 0:
            raise AssertionError(f"fixtures.py failed: {done.stderr}")

    @classmethod
    def tearDownClass(cls) -> None:
        shutil.rmtree(cls.work)

    def check(self, path):
        return libcheck.check_file(str(path), dwivedi.ABI_VERSION, dwivedi.LIBRARY_FUNCTIONS)

    def test_the_real_library_passes(self) -> None:
        self.assertIsNone(self.check(LIBRARY.resolve()))
        info, problem = libcheck.read_elf(str(LIBRARY.resolve()))
        self.assertIsNone(problem)
        self.assertEqual(info.soname, f"libdwivedi.so.{dwivedi.ABI_VERSION}")

    def test_each_bad_file(self) -> None:
        expected = {
            "aarch64": ("architecture", "is built for aarch64, this Blender runs on x86_64"),
            "i386": ("architecture", "is built for x86 (i386) (32-bit), this Blender runs on x86_64"),
            "truncated": ("damaged", "is damaged: truncated"),
            "garbage": ("damaged", "it is not an ELF file"),
            "abi0": ("too_old", "is too old: libdwivedi ABI 0 (libdwivedi.so.0), this add-on needs ABI 1"),
            "abi2": ("too_new", "is too new: libdwivedi ABI 2 (libdwivedi.so.2)"),
            "old": ("too_old", "is too old for this add-on: it lacks dwv_result_string"),
        }
        for case, (kind, fragment) in expected.items():
            with self.subTest(case=case):
                problem = self.check(self.work / case / "libdwivedi.so.1")
                self.assertIsNotNone(problem)
                self.assertEqual(problem.kind, kind, problem.message)
                self.assertIn(fragment, problem.message)
        # Only the loader can tell a missing dependency: the file itself is fine.
        self.assertIsNone(self.check(self.work / "needs" / "libdwivedi.so.1"))
        info, _ = libcheck.read_elf(str(self.work / "needs" / "libdwivedi.so.1"))
        self.assertIn("libdwivedi_test_missing.so.7", info.needed)

    def test_missing_folder_and_empty(self) -> None:
        self.assertEqual(self.check(self.work / "nowhere.so").kind, "missing")
        self.assertEqual(self.check(self.work).kind, "not_a_file")
        empty = self.work / "empty.so"
        empty.write_bytes(b"")
        self.assertIn("the file is empty", self.check(empty).message)
        for cut in (3, 20, 63):  # inside the ELF header
            short = self.work / f"short{cut}.so"
            short.write_bytes(LIBRARY.resolve().read_bytes()[:cut])
            self.assertEqual(self.check(short).kind, "damaged", cut)


if __name__ == "__main__":
    unittest.main()
