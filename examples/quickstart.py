"""irsig from Python: render the airfield demo scene (MWIR at local noon),
plot apparent temperature with matplotlib and compute the runway/grass
contrast.

    .venv/bin/python examples/quickstart.py [OUTPUT_DIR] [SIZE_PX]

Writes OUTPUT_DIR/quickstart.png (default out/) and prints the contrast.
Run by python/tests/test_example.py at a small size.
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

import irsig  # noqa: E402

root = Path(__file__).resolve().parents[1]
out = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "out"
size = int(sys.argv[2]) if len(sys.argv) > 2 else 256

# Load the scene with a smaller image than its 512 x 512 (as --set does).
scene = irsig.Scene.load(
    root / "scenes" / "airfield" / "scene.toml",
    overrides={"sensor.width_px": size, "sensor.height_px": size},
)
ds = irsig.render(scene)  # an xarray.Dataset: one variable per plane
t = ds.apparent_temperature

# Contrast between the runway (asphalt) and the irrigated grass around it.
runway = t.where(irsig.material_mask(ds, "asphalt")).mean().item()
grass = t.where(irsig.material_mask(ds, "grass_irrigated")).mean().item()
l_run = ds.band_radiance.where(irsig.material_mask(ds, "asphalt")).mean().item()
l_grass = ds.band_radiance.where(irsig.material_mask(ds, "grass_irrigated")).mean().item()
michelson = (l_run - l_grass) / (l_run + l_grass)
print(f"{ds.attrs['band']} at {ds.attrs['image_time_local']} local, sun zenith {ds.attrs['sun_zenith_deg']:.1f} deg")
print(f"runway {runway:.2f} K, grass {grass:.2f} K: contrast {runway - grass:+.2f} K (Michelson {michelson:+.4f})")

fig, ax = plt.subplots(figsize=(6, 5))
t.plot.imshow(ax=ax, cmap="inferno", yincrease=False, robust=True)
ax.set_title(f"airfield, {ds.attrs['band']}, {ds.attrs['image_time_local']} local")
ax.set_aspect("equal")
out.mkdir(parents=True, exist_ok=True)
fig.savefig(out / "quickstart.png", dpi=100, bbox_inches="tight")
print(f"wrote {out / 'quickstart.png'}")
