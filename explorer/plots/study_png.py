"""The design chart of a study as a PNG file, drawn on the server with Pillow.

The page's chart is drawn by the browser; the file must not depend on one (a print-out,
a handout), and the server has no plotting library but Pillow (a Bokeh dependency). The
picture shows what the page shows: a line over one parameter or a heat map over two,
axis names with units, flagged points as red crosses, failed points left out (grey
cells), and a note with the counts. Nothing here imports Panel.
"""

from __future__ import annotations

import io
import math

import numpy as np
from bokeh.palettes import Viridis256
from PIL import Image, ImageDraw, ImageFont

from ..model import StudyResult
from .study import chart_title, flag_note, fmt, tick_indices

#: Size of the picture [px].
WIDTH, HEIGHT = 900, 560
# plot area: left, top, right, bottom margins [px]
_LEFT, _TOP, _RIGHT, _BOTTOM = 90, 50, 130, 95
_LINE = (31, 119, 180)
_FLAG = (214, 39, 40)
_GREY = (204, 204, 204)
_INK = (40, 40, 40)


def _font(size: int) -> ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # a Pillow without FreeType: its one bitmap font
        return ImageFont.load_default()


def _hex(color: str) -> tuple[int, int, int]:
    return tuple(int(color[k:k + 2], 16) for k in (1, 3, 5))  # type: ignore[return-value]


def _nice_ticks(lo: float, hi: float, n: int = 6) -> list[float]:
    """About ``n`` round numbers between ``lo`` and ``hi``."""
    if not hi > lo:
        return [lo]
    step = 10 ** math.floor(math.log10((hi - lo) / n))
    for m in (1, 2, 5, 10):
        if (hi - lo) / (m * step) <= n:
            step *= m
            break
    first = math.ceil(lo / step) * step
    return [first + k * step for k in range(int((hi - first) / step) + 1)]


def _cross(draw: ImageDraw.ImageDraw, x: float, y: float, r: float = 6) -> None:
    draw.line([(x - r, y - r), (x + r, y + r)], fill=_FLAG, width=3)
    draw.line([(x - r, y + r), (x + r, y - r)], fill=_FLAG, width=3)


def design_chart_png(result: StudyResult, output: str, time_index: int) -> bytes:
    """The chart of ``output`` at output time ``time_index`` as PNG bytes."""
    image = Image.new("RGB", (WIDTH, HEIGHT), "white")
    draw = ImageDraw.Draw(image)
    small, normal = _font(13), _font(16)
    x0, y0, x1, y1 = _LEFT, _TOP, WIDTH - _RIGHT, HEIGHT - _BOTTOM
    planned = result.planned
    z = result.shown(output, time_index)
    name, unit, _ = result.planned.outputs[output]
    draw.text((_LEFT, 15), chart_title(result, output, time_index), fill=_INK, font=normal)
    scene = str(planned.study.base.get("name", ""))[:90]
    draw.text((_LEFT, HEIGHT - 28), f"{flag_note(result)} · scene: {scene}", fill=_INK,
              font=small)
    first = planned.choices[0]
    draw.text(((x0 + x1) / 2, y1 + 40), first.title, fill=_INK, font=normal, anchor="mt")
    if len(planned.values) == 1:
        _line_chart(draw, result, z, (x0, y0, x1, y1), small)
        _vertical_text(image, f"{name} [{unit}]", (20, (y0 + y1) / 2), normal)
    else:
        _heat_map(draw, result, z, (x0, y0, x1, y1), small, normal)
        _vertical_text(image, planned.choices[1].title, (20, (y0 + y1) / 2), normal)
        # the colour bar's own label (its unit was only in the title)
        _vertical_text(image, f"{name} [{unit}]", (WIDTH - 16, (y0 + y1) / 2), normal)
    draw.rectangle([x0, y0, x1, y1], outline=_INK)
    out = io.BytesIO()
    image.save(out, format="PNG")
    return out.getvalue()


def _vertical_text(image: Image.Image, text: str, centre: tuple[float, float],
                   font: ImageFont.ImageFont) -> None:
    box = ImageDraw.Draw(image).textbbox((0, 0), text, font=font)
    label = Image.new("RGB", (box[2] + 4, box[3] + 4), "white")
    ImageDraw.Draw(label).text((2, 2), text, fill=_INK, font=font)
    label = label.rotate(90, expand=True)
    image.paste(label, (int(centre[0] - label.width / 2), int(centre[1] - label.height / 2)))


def _line_chart(draw: ImageDraw.ImageDraw, result: StudyResult, z: np.ndarray,
                box: tuple[int, int, int, int], font: ImageFont.ImageFont) -> None:
    x0, y0, x1, y1 = box
    planned = result.planned
    x = planned.values[0]
    log = planned.is_log(0)
    u = np.log10(x) if log else x
    ok = np.isfinite(z)
    lo, hi = (float(z[ok].min()), float(z[ok].max())) if ok.any() else (0.0, 1.0)
    pad = 0.08 * (hi - lo) if hi > lo else 0.5 * (abs(lo) or 1.0)
    lo, hi = lo - pad, hi + pad

    def px(v: float) -> float:
        return x0 + (v - u.min()) / (u.max() - u.min()) * (x1 - x0)

    def py(v: float) -> float:
        return y1 - (v - lo) / (hi - lo) * (y1 - y0)

    for t in _nice_ticks(lo, hi):
        draw.line([(x0 - 5, py(t)), (x0, py(t))], fill=_INK)
        draw.text((x0 - 8, py(t)), fmt(t), fill=_INK, font=font, anchor="rm")
    xticks = ([10.0 ** k for k in range(math.floor(u.min()), math.ceil(u.max()) + 1)
               if u.min() <= k <= u.max()] or [x[0], x[-1]]) if log else \
        _nice_ticks(float(x.min()), float(x.max()))
    for t in xticks:
        p = px(math.log10(t) if log else t)
        draw.line([(p, y1), (p, y1 + 5)], fill=_INK)
        draw.text((p, y1 + 8), fmt(t), fill=_INK, font=font, anchor="mt")
    points = [(px(a), py(b)) if math.isfinite(b) else None for a, b in zip(u, z, strict=True)]
    run: list[tuple[float, float]] = []
    for p in points + [None]:
        if p is None:
            if len(run) > 1:
                draw.line(run, fill=_LINE, width=3)
            run = []
        else:
            run.append(p)
    for p, flagged in zip(points, result.flagged, strict=True):
        if p is not None:
            draw.ellipse([p[0] - 4, p[1] - 4, p[0] + 4, p[1] + 4], fill=_LINE)
            if flagged:
                _cross(draw, *p)


def _heat_map(draw: ImageDraw.ImageDraw, result: StudyResult, z: np.ndarray,
              box: tuple[int, int, int, int], font: ImageFont.ImageFont,
              title_font: ImageFont.ImageFont) -> None:
    x0, y0, x1, y1 = box
    planned = result.planned
    n1, n2 = planned.shape
    w, h = (x1 - x0) / n1, (y1 - y0) / n2
    ok = np.isfinite(z)
    lo, hi = (float(z[ok].min()), float(z[ok].max())) if ok.any() else (0.0, 1.0)
    span = hi - lo if hi > lo else 1.0
    palette = [_hex(c) for c in Viridis256]
    for i in range(n1):
        for j in range(n2):
            v = z[i, j]
            color = _GREY if not math.isfinite(v) else \
                palette[min(255, int((v - lo) / span * 255))]
            draw.rectangle([x0 + i * w, y1 - (j + 1) * h, x0 + (i + 1) * w, y1 - j * h],
                           fill=color)
    for i, j in zip(*np.nonzero(result.flagged), strict=True):
        _cross(draw, x0 + (i + 0.5) * w, y1 - (j + 0.5) * h, r=min(6, w / 3, h / 3))
    for k in tick_indices(n1):
        p = x0 + (k + 0.5) * w
        draw.line([(p, y1), (p, y1 + 5)], fill=_INK)
        draw.text((p, y1 + 8), fmt(float(planned.values[0][k])), fill=_INK, font=font,
                  anchor="mt")
    for k in tick_indices(n2):
        p = y1 - (k + 0.5) * h
        draw.line([(x0 - 5, p), (x0, p)], fill=_INK)
        draw.text((x0 - 8, p), fmt(float(planned.values[1][k])), fill=_INK, font=font,
                  anchor="rm")
    # colour bar
    bx0, bx1 = x1 + 20, x1 + 38
    for k in range(y1 - y0):
        draw.line([(bx0, y1 - k), (bx1, y1 - k)], fill=palette[int(k / (y1 - y0) * 255)])
    draw.rectangle([bx0, y0, bx1, y1], outline=_INK)
    for t in _nice_ticks(lo, hi, 5):
        p = y1 - (t - lo) / span * (y1 - y0)
        draw.text((bx1 + 4, p), fmt(t), fill=_INK, font=font, anchor="lm")
