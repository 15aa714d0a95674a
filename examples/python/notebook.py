# %% [markdown]
# # A city as arrays, a path and a frame
#
# A notebook in the percent format (Jupyter, VS Code and jupytext open it as cells; `python3`
# runs it as a script). It generates a small city, draws its streets, lanes, buildings, trees
# and a car path as a map from the arrays, renders the frame at the path's middle and puts the
# map, the frame and its depth side by side in one picture (needs python3-pil):
#
#     PYTHONPATH=build/python xvfb-run -a python3 examples/python/notebook.py docs/img/python_notebook.png

# %%
import sys

import numpy as np
from PIL import Image, ImageDraw

import vista

city = vista.generate(seed=11, size_m=500)
print(city, city.stats["buildings"], "buildings,", city.stats["trees"], "trees")

# %% [markdown]
# The arrays: street nodes and edges, lanes (centre lines in their direction of travel),
# building footprints, trees. World metres, x east, y north.

# %%
streets, lanes, trees = city.streets, city.lanes, city.trees
footprints = city.building_footprints
path = vista.path(city, kind="car", seed=3, duration=20)
print(len(streets["edges"]), "street edges,", len(lanes), "lanes,", len(path), "path samples")

# %% [markdown]
# A map drawn from the arrays alone.

# %%
H = 480
half = city.params["size_m"] / 2


def to_px(xy):
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    return [((x + half) / (2 * half) * (H - 1), (half - y) / (2 * half) * (H - 1)) for x, y in xy]


m = Image.new("RGB", (H, H), (236, 232, 224))
d = ImageDraw.Draw(m)
for ring in footprints:
    d.polygon(to_px(ring), fill=(176, 160, 150))
nodes = streets["nodes"]
for e in streets["edges"]:
    d.line(to_px(nodes[[e["a"], e["b"]]]), fill=(90, 90, 96), width=3)
for ln in lanes:
    d.line(to_px([(ln["x0"], ln["y0"]), (ln["x1"], ln["y1"])]), fill=(250, 250, 250), width=1)
for x, y in to_px(np.stack([trees["x"], trees["y"]], axis=1)):
    d.ellipse((x - 1.5, y - 1.5, x + 1.5, y + 1.5), fill=(60, 130, 60))
d.line(to_px(path.position[:, :2]), fill=(220, 40, 40), width=3)

# %% [markdown]
# The frame at the path's middle: rgb and depth (near dark, far light, sky white).

# %%
pose = path[len(path) // 2]
px = to_px(pose.position[:2])[0]
d.ellipse((px[0] - 5, px[1] - 5, px[0] + 5, px[1] + 5), outline=(220, 40, 40), width=2)
frame = vista.Renderer(city, mode="hybrid", size=(640, H), channels=["rgb", "depth"]).render(pose)
depth = frame["depth"]
shade = np.where(np.isfinite(depth), np.clip(np.log1p(depth) / np.log1p(500.0), 0, 1), 1.0)
depth_img = Image.fromarray((shade * 255).astype(np.uint8)).convert("RGB")

# %%
out = Image.new("RGB", (H + 640 + 320, H), (255, 255, 255))
out.paste(m, (0, 0))
out.paste(Image.fromarray(np.ascontiguousarray(frame["rgb"])), (H, 0))
out.paste(depth_img.resize((320, H // 2)), (H + 640, 0))
if len(sys.argv) > 1:
    out.save(sys.argv[1])
    print("->", sys.argv[1])
