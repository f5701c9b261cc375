"""PNG and SVG of a figure from one layout (issue 31): the same images as matplotlib's own tight savefig."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest

from stickslip.plots.export import PNG_DPI, png_and_svg_bytes

pytest.importorskip("matplotlib")


def _figure(layout: str | None = "constrained", outside: bool = False):  # type: ignore[no-untyped-def]
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.0, 3.0), layout=layout)
    ax = fig.add_subplot()
    x = np.linspace(0.0, 10.0, 200)
    ax.plot(x, np.sin(x), label=r"$\sigma_s$ (Pa)")
    ax.set_xlabel("sliding velocity V (µm/s)")
    ax.set_title(r"$V_c$ and $\tau_a$")
    ax.legend()
    if outside:  # an artist past the figure's right edge: the tight box reaches beyond the raster
        fig.text(1.15, 0.5, "far out on the right")
    return fig


def _pixels(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), dtype=float)


def _blocks(pixels: np.ndarray, size: int = 6) -> np.ndarray:
    rows, cols = (pixels.shape[0] // size) * size, (pixels.shape[1] // size) * size
    return pixels[:rows, :cols].reshape(rows // size, size, cols // size, size, -1).mean(axis=(1, 3))


def _reference(fig) -> tuple[bytes, bytes]:  # type: ignore[no-untyped-def]
    png, svg = io.BytesIO(), io.BytesIO()
    fig.savefig(png, format="png", dpi=PNG_DPI, bbox_inches="tight")
    fig.savefig(svg, format="svg", bbox_inches="tight")
    return png.getvalue(), svg.getvalue()


def _svg_size(svg: bytes) -> tuple[float, float]:
    found = re.search(rb'width="([0-9.]+)pt" height="([0-9.]+)pt"', svg)
    assert found is not None
    return float(found.group(1)), float(found.group(2))


@pytest.mark.parametrize(("layout", "outside"), [("constrained", False), ("tight", False), (None, True)])
def test_same_images_as_two_tight_savefig_calls(layout: str | None, outside: bool) -> None:
    fig = _figure(layout, outside)
    png, svg = png_and_svg_bytes(fig)
    ref_png, ref_svg = _reference(_figure(layout, outside))
    new, ref = _pixels(png), _pixels(ref_png)
    assert abs(new.shape[0] - ref.shape[0]) <= 1 and abs(new.shape[1] - ref.shape[1]) <= 1  # savefig's size
    rows, cols = min(new.shape[0], ref.shape[0]), min(new.shape[1], ref.shape[1])
    new, ref = new[:rows, :cols], ref[:rows, :cols]
    # the same picture up to the antialiasing of a layout placed a fraction of a pixel apart: in 6 x 6 pixel
    # blocks, far closer to savefig's image than savefig's image is to itself moved by three pixels
    moved = np.abs(_blocks(ref[:, 3:]) - _blocks(ref[:, :-3])).mean()
    assert np.abs(_blocks(new) - _blocks(ref)).mean() < 0.5 * moved
    width, height = _svg_size(svg)
    ref_width, ref_height = _svg_size(ref_svg)
    assert abs(width - ref_width) < 2.0 and abs(height - ref_height) < 2.0  # points: the same box
    assert svg.startswith(b"<?xml") and b"</svg>" in svg


def test_padding_past_the_figure_is_its_face_colour() -> None:
    fig = _figure("constrained")
    fig.set_facecolor("#ffeecc")
    pixels = _pixels(png_and_svg_bytes(fig)[0])
    assert np.all(pixels[0, :, :3] == [255, 238, 204]) and np.all(pixels[:, -1, :3] == [255, 238, 204])


def test_the_figure_is_left_as_it_was() -> None:
    fig = _figure("constrained")
    dpi, engine, canvas = fig.dpi, fig.get_layout_engine(), fig.canvas
    png_and_svg_bytes(fig)
    assert (fig.dpi, fig.get_layout_engine(), fig.canvas) == (dpi, engine, canvas)
