"""The add-on's export gives one mesh the same normals every time (blender_addon/dwivedi_bake/
normals.py), in headless Blender: Blender 3.x's own vertex normals change in their last bits from
one evaluation to the next when its threads are scheduled differently (atomic float additions in
any order), which made two bakes of one scene differ in the last bits of some pixels (the add-on's
bake against its farm chunks: blender.test_farm's intermittent 1-ulp failure).

A 48 x 24 UV sphere, smooth, baked (8 x 8 pixels, 2 spp) 5 times and evaluated 40 times while two
other processes keep the cores busy (as a loaded machine does; on an idle one Blender's normals
rarely move): the exported normals (per vertex: the sphere is all smooth) are the same bits every
time and within 1e-5 of Blender's (which computes them in float and loses about 3e-6 on the poles'
thin triangles), and the 5 bakes, each from its own export (the export cache emptied before
each, as a farm export is an export of its own), are the same bits.
How many distinct normal arrays Blender itself gave is printed (1 to 4 in 12 to 40 evaluations in
Blender 3.4.1 here). Without normals.py it failed by chance: the export before export20's failed 3
of 4 runs (3 distinct exported arrays, or 2 distinct images in the 5 bakes), export20's (vertex
normals read from Blender for all-smooth meshes) 2 of 8; with it, a sure pass. The deterministic
check is tests/python/test_normals.py.

    blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_export_normals.py
(through ctest, which sets the user folders and the zip's path: see harness.py)
"""
import array
import hashlib
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bpy  # noqa: E402

import harness  # noqa: E402
import scenes  # noqa: E402

WORK = harness.install_addon()
EVALUATIONS = 40
BAKES = 5
BUSY = "import time\nend = time.monotonic() + 30\nwhile time.monotonic() < end: pass\n"


def blender_normals(mesh, per_vertex):
    """Blender's own normals of `mesh`, per vertex or per loop-triangle corner, as the export's."""
    if per_vertex:
        out = array.array("f", bytes(12 * len(mesh.vertices)))
        if hasattr(mesh, "vertex_normals"):
            mesh.vertex_normals.foreach_get("vector", out)
        else:
            mesh.vertices.foreach_get("normal", out)
        return out
    mesh.calc_loop_triangles()
    if hasattr(mesh, "calc_normals_split"):
        mesh.calc_normals_split()
    out = array.array("f", bytes(36 * len(mesh.loop_triangles)))
    mesh.loop_triangles.foreach_get("split_normals", out)
    return out


class ExportNormalsTest(harness.unittest.TestCase):
    def test_the_same_normals_every_export(self):
        export = harness.addon_module("export")
        scene = scenes.sphere_scene(resolution=8, samples=2)
        sphere = bpy.data.objects["Sphere"]
        busy = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(2)]
        exported, own, bakes = set(), set(), []
        try:
            time.sleep(0.5)  # both running
            # A bake first: the library's idle threads beside Blender's make its normals move more.
            bakes.append(harness.dwivedi_bake(scene, 3, 2, WORK / "bake")[0])
            for _ in range(EVALUATIONS):
                evaluated = sphere.evaluated_get(bpy.context.evaluated_depsgraph_get())
                mesh = evaluated.to_mesh()
                try:
                    ours = export._mesh_arrays(mesh, want_uvs=False)["normals"]
                    theirs = blender_normals(mesh, per_vertex=len(ours) == 3 * len(mesh.vertices))
                finally:
                    evaluated.to_mesh_clear()
                exported.add(hashlib.sha1(bytes(ours)).hexdigest())
                own.add(hashlib.sha1(bytes(theirs)).hexdigest())
                self.assertLess(max(abs(a - b) for a, b in zip(ours, theirs)), 1e-5)
            for _ in range(BAKES - 1):
                export.CACHE.clear()  # each bake from an export of its own, as the farm export is
                bakes.append(harness.dwivedi_bake(scene, 3, 2, WORK / "bake")[0])
        finally:
            for process in busy:
                process.kill()
                process.wait()
        print(f"Blender's own normals: {len(own)} distinct arrays in {EVALUATIONS} evaluations; "
              f"the export's: {len(exported)}; distinct images in {BAKES} bakes: {len(set(map(tuple, bakes)))}",
              flush=True)
        self.assertEqual(len(exported), 1, "the export's normals changed from one evaluation to the next")
        for k, image in enumerate(bakes[1:], 2):
            self.assertEqual(image, bakes[0], f"bake {k} of one scene differs from the first")


harness.run(ExportNormalsTest)
