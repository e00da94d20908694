"""Measure our renderer's antialiasing options against Helios: cost per view and fidelity.

    .venv/bin/python tools/antialiasing.py [--crops strawberry,vine] [--size 1280x720] \
        [--doc docs/performance.md]

For each crop a scene is grown (dataset seed 0, scene 0), a few of its views are drawn by Helios's
Visualizer (the reference: 4x multisampled colour, ids from a 1x pass) and by our renderer in the
``helios`` look with each option:

- ``1x``: one 1x pass writes colour, ids and depth (no antialiasing; the baseline);
- ``1x + FXAA on silhouettes``: that pass, then FXAA where the depth jumps (our default);
- ``4x colour + 1x ids``: colour with 4x multisampling, then a light 1x pass for ids and depth;
- ``4x per-sample``: one 4x multisampled pass writes colour, ids and depth; the colour is averaged,
  the ids and depth are taken from one sample of each pixel (no sample lies at the pixel centre,
  where Helios's id pass and our 1x passes sample).

Reported per option: the median over interleaved repetitions of wall and CPU milliseconds per
view (draw and read-back), pixels whose id differs from Helios's, the lowest IoU of a fruit mask
with Helios's (fruit of at least 100 pixels), the largest box difference and the mean absolute
colour difference. With ``--doc`` the table is written between the file's
``<!-- antialiasing:start -->`` and ``<!-- antialiasing:end -->`` markers.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import write_marked_section
from davis_ag.generate.one_scene import SceneRequest, grow_scene
from davis_ag.labels.fruit_labels import fruit_lookup, label_view
from davis_ag.render.helios import HeliosRenderer
from davis_ag.render.opengl import OpenGLRenderer
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS

GRIDS = {"strawberry": dataclasses.replace(SCENARIOS["sp"], extent=(2.5, 3.0), step=0.5, altitude_levels=(1,)),
         "vine": dataclasses.replace(SCENARIOS["sp"], step=1.0, altitude_levels=(0,))}
VIEWS = 4
REPEATS = 3
MIN_FRUIT = 100

RESOLVE = """
#version 330 core
uniform usampler2DMS ids;
uniform sampler2DMS depths;
layout(location = 0) out uint out_id;
layout(location = 1) out float out_depth;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    out_id = texelFetch(ids, p, 0).r;
    out_depth = texelFetch(depths, p, 0).r;
}
"""


class PerSample:
    """Our renderer's 4x pass with ids and depth kept per sample, resolved from sample 0."""

    def __init__(self, renderer: OpenGLRenderer) -> None:
        with renderer.ctx:  # its objects live in the renderer's context, whichever is current now
            self._build(renderer)

    def _build(self, renderer: OpenGLRenderer) -> None:
        ctx, w, h = renderer.ctx, renderer.camera.width, renderer.camera.height
        self.renderer = renderer
        colour = ctx.texture((w, h), 4, samples=4)  # all attachments textures: a complete framebuffer
        self.ids = ctx.texture((w, h), 1, dtype="u4", samples=4)
        self.depths = ctx.texture((w, h), 1, dtype="f4", samples=4)
        self.fbo = ctx.framebuffer([colour, self.ids, self.depths], ctx.depth_texture((w, h), samples=4))
        self.colour_only = ctx.framebuffer([colour])
        sky_vertex = (Path(__file__).parents[1] / "src/davis_ag/render/shaders/sky.vert").read_text()
        self.program = ctx.program(vertex_shader=sky_vertex, fragment_shader=RESOLVE)
        self.program["ids"], self.program["depths"] = 3, 4
        self.vao = ctx.vertex_array(self.program, [])

    def render(self, view) -> tuple[np.ndarray, np.ndarray, np.ndarray]:

        r = self.renderer
        with r.ctx:
            return self._render(view)

    def _render(self, view) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        import moderngl

        r = self.renderer
        r._view_uniforms(view)
        r._bind_textures()
        r.ctx.enable(moderngl.DEPTH_TEST)
        r.ctx.depth_func = "<="
        r.ctx.polygon_offset = (1.0, 1.0)
        r._pass(self.fbo, r._scene)
        r.ctx.copy_framebuffer(r._resolve_fbo, self.colour_only)
        r._ids_fbo.use()
        r.ctx.disable(moderngl.DEPTH_TEST)
        self.ids.use(3)
        self.depths.use(4)
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        return r.read()


def cpu() -> float:
    times = os.times()
    return times.user + times.system


def measure(crop: str, camera: Camera) -> list[dict]:
    """Fidelity and cost of every option on one crop's scene."""
    request = SceneRequest(GRIDS[crop], CROPS[crop], 0, 0, camera)
    model, grid = grow_scene(request)
    views = list(grid.viewpoints[:VIEWS])
    lookup = fruit_lookup({f.id: f.uuids for f in model.fruits}, model.uuid_count)
    with HeliosRenderer(model.context, camera, model.lighting) as helios:
        reference = [helios.render(v, depth=False) for v in views]
    one = OpenGLRenderer(model.context, camera, model.lighting, look="helios", antialiasing="none")
    fxaa = OpenGLRenderer(model.context, camera, model.lighting, look="helios", antialiasing="fxaa")
    four = OpenGLRenderer(model.context, camera, model.lighting, look="helios", antialiasing="msaa")
    options = {"1x": one.render, "1x + FXAA on silhouettes": fxaa.render, "4x colour + 1x ids": four.render,
               "4x per-sample": PerSample(four).render}
    timings: dict[str, list[tuple[float, float]]] = {name: [] for name in options}
    frames: dict[str, list] = {}
    for _ in range(REPEATS):
        for name, render in options.items():
            render(views[0])
            start, start_cpu = time.perf_counter(), cpu()
            frames[name] = [render(v) for v in views]
            timings[name].append(((time.perf_counter() - start) / len(views), (cpu() - start_cpu) / len(views)))
    for renderer in (one, fxaa, four):
        renderer.close()
    rows = []
    for name in options:
        differ, ious, box_error, colour = 0, [], 0, []
        for ours, ref in zip(frames[name], reference):
            differ += int((ours[1] != ref[1]).sum())
            colour.append(float(np.abs(ours[0].astype(np.int16) - ref[0]).mean()))
            mine, theirs = label_view(ours[1], lookup, MIN_FRUIT), label_view(ref[1], lookup, MIN_FRUIT)
            boxes = {b[4]: b for b in theirs.boxes}
            for box in mine.boxes:
                a, b = mine.segmentation == box[4], theirs.segmentation == box[4]
                ious.append(float((a & b).sum() / (a | b).sum()))
                if box[4] in boxes:
                    box_error = max(box_error, int(np.abs(np.subtract(box[:4], boxes[box[4]][:4])).max()))
        pixels = len(views) * camera.width * camera.height
        rows.append({"crop": crop, "plants": model.plant_generator, "option": name,
                     "wall_ms": 1000 * statistics.median(t[0] for t in timings[name]),
                     "cpu_ms": 1000 * statistics.median(t[1] for t in timings[name]),
                     "ids_differ_percent": 100 * differ / pixels, "min_fruit_iou": min(ious, default=1.0),
                     "max_box_error_px": box_error, "mean_colour_difference": statistics.mean(colour)})
    return rows


def table(rows: list[dict], camera: Camera) -> str:
    """The Markdown table, and which option is fastest among those meeting the criteria."""
    plants = ", ".join(sorted({row["plants"] for row in rows}))
    lines = [f"{camera.width}x{camera.height}, `--plants {plants}`, {VIEWS} views per crop, median of {REPEATS} "
             "interleaved repetitions, "
             f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs at the end.", "",
             "| crop | option | wall ms/view | CPU ms/view | ids differ | min fruit IoU | max box error | "
             "mean colour difference | meets the criteria |", "|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        row["meets"] = (row["ids_differ_percent"] <= 0.01 and row["min_fruit_iou"] >= 0.999
                        and row["max_box_error_px"] <= 1 and row["mean_colour_difference"] <= 2.0)
        lines.append(f"| {row['crop']} | {row['option']} | {row['wall_ms']:.0f} | {row['cpu_ms']:.0f} | "
                     f"{row['ids_differ_percent']:.4f} % | {row['min_fruit_iou']:.4f} | {row['max_box_error_px']} px | "
                     f"{row['mean_colour_difference']:.2f}/255 | {'yes' if row['meets'] else 'no'} |")
    antialiased = [r for r in rows if r["option"] != "1x"]
    by_option: dict[str, list[dict]] = {}
    for row in antialiased:
        by_option.setdefault(row["option"], []).append(row)
    passing = {k: sum(r["cpu_ms"] for r in v) for k, v in by_option.items() if all(r["meets"] for r in v)}
    if passing:
        best = min(passing, key=passing.get)
        lines += ["", f"Fastest antialiased option meeting every criterion on every crop: **{best}**."]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--crops", default="strawberry,vine")
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--doc", type=Path)
    args = parser.parse_args()
    camera = Camera(*(int(v) for v in args.size.split("x")))
    rows = [row for crop in args.crops.split(",") for row in measure(crop, camera)]
    text = table(rows, camera)
    print(text)
    if args.doc:
        write_marked_section(args.doc, "antialiasing", text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
