"""bench/run export: each export of a run (time: median of 5 `mrtmap export` calls; size) and the
verdict of the tool that reads it, beside that tool's own time to read it; the report's size and
its 3D view's share.

    python bench/export_check.py MRTMAP RUN_DIR NPM_DIR
"""

import importlib.util
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

mrtmap, run, npm = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
tmp = Path(tempfile.mkdtemp())


def timed(f, n=5):
    ts = []
    for _ in range(n):
        t0 = time.perf_counter()
        r = f()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts), r


def export(name):
    out = tmp / name
    subprocess.run([mrtmap, "export", str(run), "--out", str(out)], check=True, capture_output=True)
    return out


for name in ("room.hbjson", "room.xml", "room.glb", "room.rad"):
    secs, out = timed(lambda: export(name))
    line = f"  {name:<12} {out.stat().st_size / 1e3:8.1f} kB, mrtmap export {secs * 1e3:6.0f} ms (whole command)"
    if name.endswith(".hbjson"):
        from honeybee.model import Model
        from honeybee_schema.model import Model as Schema

        t, m = timed(lambda: Model.from_hbjson(str(out)))
        Schema.model_validate(json.loads(out.read_text()))
        r = m.rooms[0]
        ok = m.check_all(raise_exception=False) == ""
        line += (f"; honeybee-core reads it in {t * 1e3:.0f} ms: check_all {'clean' if ok else 'FAILS'}, "
                 f"solid {r.geometry.is_solid}, {len(r.faces)} faces, {len(r.apertures)} apertures, "
                 f"floor {r.floor_area:.2f} m², volume {r.volume:.2f} m³; honeybee-schema valid")
    elif name.endswith(".xml"):
        from lxml import etree

        xsd = Path(importlib.util.find_spec("xgbxml").origin).parent / "schemas" / "GreenBuildingXML_Ver6.01.xsd"
        schema = etree.XMLSchema(etree.parse(str(xsd)))
        t, ok = timed(lambda: schema.validate(etree.parse(str(out))))
        line += f"; lxml XSD (gbXML 6.01) {'valid' if ok else 'INVALID'} in {t * 1e3:.0f} ms"
    elif name.endswith(".glb"):
        js = ("const v=require('gltf-validator');const fs=require('fs');"
              "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[1])))"
              ".then(r=>console.log(JSON.stringify(r.issues)))")
        t0 = time.perf_counter()
        r = subprocess.run(["node", "-e", js, str(out)], cwd=npm, capture_output=True, text=True, check=True)
        t = time.perf_counter() - t0
        iss = json.loads(r.stdout)
        import pygltflib

        g = pygltflib.GLTF2().load(str(out))
        pts = sum(g.accessors[p.attributes.POSITION].count for m in g.meshes for p in m.primitives if p.mode == 0)
        line += (f"; gltf-validator {iss['numErrors']} errors, {iss['numWarnings']} warnings ({t:.1f} s); "
                 f"pygltflib: {len(g.meshes)} meshes, {pts} cloud points")
    else:
        from honeybee_radiance.reader import string_to_dicts

        t, prims = timed(lambda: string_to_dicts(out.read_text()))
        line += f"; honeybee-radiance parses {len(prims)} primitives in {t * 1e3:.0f} ms"
    print(line)

html = (run / "report.html").read_text()
i = html.find('id="view3d-data">')
j = html.find("</script>", i)
view = j - i if i >= 0 else 0
print(f"  report.html {len(html.encode()) / 1e6:.2f} MB, of which the 3D view's data {view / 1e6:.2f} MB")
