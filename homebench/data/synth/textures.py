"""Procedural grey-level textures (albedo in [0, 1], float32, row 0 at the top).

Every painter takes a numpy ``Generator`` and a pixel shape ``(rows, cols)`` and draws only from
that generator, so a seeded layout always paints the same room.
"""

from __future__ import annotations

import string
from functools import lru_cache

import cv2
import numpy as np
from matplotlib import cbook
from numpy.typing import NDArray

Texture = NDArray[np.float32]
Rng = np.random.Generator

#: matplotlib's bundled sample images used as posters.
SAMPLE_IMAGES = ("grace_hopper.jpg", "Minduka_Present_Blue_Pack.png", "logo2.png")
#: matplotlib's bundled elevation arrays, shown as grey images: (file, array name).
SAMPLE_ARRAYS = (("jacksboro_fault_dem.npz", "elevation"), ("topobathy.npz", "topo"))


# --------------------------------------------------------------------------- basics


def noise(rng: Rng, shape: tuple[int, int], cell: float, octaves: int = 3) -> Texture:
    """Smooth fractal value noise of ``shape``, zero mean, roughly unit std; ``cell`` in px."""
    h, w = shape
    out = np.zeros(shape, np.float32)
    amplitude, total = 1.0, 0.0
    for _ in range(octaves):
        gh, gw = max(2, int(np.ceil(h / cell)) + 1), max(2, int(np.ceil(w / cell)) + 1)
        grid = rng.standard_normal((gh, gw)).astype(np.float32)
        out += amplitude * cv2.resize(grid, (w, h), interpolation=cv2.INTER_CUBIC)
        total += amplitude
        amplitude *= 0.5
        cell = max(1.0, cell / 2.0)
    return out / total


def fit(image: NDArray, shape: tuple[int, int]) -> Texture:
    """Resize ``image`` (any 2-D array) to ``shape`` (rows, cols), float32."""
    interp = cv2.INTER_AREA if image.shape[0] > shape[0] else cv2.INTER_LINEAR
    return cv2.resize(image.astype(np.float32), (shape[1], shape[0]), interpolation=interp)


def normalise(image: NDArray, low: float = 0.05, high: float = 0.95) -> Texture:
    """Stretch ``image`` linearly to [low, high]."""
    a = image.astype(np.float32)
    span = float(a.max() - a.min()) or 1.0
    return low + (high - low) * (a - a.min()) / span


def fill_rect(tex: Texture, r0: int, c0: int, r1: int, c1: int, value: float | Texture) -> None:
    """Paint rows [r0, r1) x cols [c0, c1) (clipped to the texture) with a value or a patch."""
    h, w = tex.shape
    a0, b0, a1, b1 = max(r0, 0), max(c0, 0), min(r1, h), min(c1, w)
    if a1 <= a0 or b1 <= b0:
        return
    if isinstance(value, np.ndarray):
        value = value[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0]
    tex[a0:a1, b0:b1] = value


def frame(tex: Texture, r0: int, c0: int, r1: int, c1: int, width: int, value: float) -> None:
    """Draw a rectangular border of ``width`` px inside the rectangle."""
    fill_rect(tex, r0, c0, r0 + width, c1, value)
    fill_rect(tex, r1 - width, c0, r1, c1, value)
    fill_rect(tex, r0, c0, r1, c0 + width, value)
    fill_rect(tex, r0, c1 - width, r1, c1, value)


def random_word(rng: Rng, n: int) -> str:
    letters = string.ascii_uppercase + string.digits
    return "".join(rng.choice(list(letters), size=n))


def text_lines(
    tex: Texture, rng: Rng, rect: tuple[int, int, int, int], value: float, scale: float
) -> None:
    """Fill ``rect`` (r0, c0, r1, c1) with lines of random words in a Hershey font."""
    r0, c0, r1, c1 = rect
    line = max(4, int(30 * scale))
    thickness = max(1, int(round(2 * scale)))
    ink = np.zeros(tex.shape, np.uint8)  # cv2.putText draws on 8-bit images only
    for baseline in range(r0 + line, r1 - 2, int(line * 1.5)):
        x = c0 + 2
        while x < c1 - 4 * line:
            word = random_word(rng, int(rng.integers(2, 8)))
            cv2.putText(
                ink,
                word,
                (x, baseline),
                cv2.FONT_HERSHEY_SIMPLEX,
                scale,
                255,
                thickness,
                cv2.LINE_AA,
            )
            x += int(line * 0.6 * (len(word) + 1))
    alpha = ink.astype(np.float32) / 255.0
    tex *= 1.0 - alpha
    tex += value * alpha


def blank(shape: tuple[int, int], value: float) -> Texture:
    return np.full(shape, value, np.float32)


# --------------------------------------------------------------------------- sample data


@lru_cache(maxsize=8)
def _sample_image(name: str) -> Texture:
    with cbook.get_sample_data(name) as f:
        buffer = np.frombuffer(f.read(), np.uint8)
    image = cv2.imdecode(buffer, cv2.IMREAD_UNCHANGED)
    if image.ndim == 3 and image.shape[2] == 4:  # composite on white
        alpha = image[..., 3:4].astype(np.float32) / 255.0
        image = (image[..., :3] * alpha + 255.0 * (1.0 - alpha)).astype(np.uint8)
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    return normalise(image, 0.0, 1.0)


@lru_cache(maxsize=4)
def _sample_array(name: str, key: str) -> Texture:
    data = cbook.get_sample_data(name)
    return normalise(np.asarray(data[key], np.float32), 0.0, 1.0)


# --------------------------------------------------------------------------- posters


def poster(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A framed poster: a sample photo, an elevation map, shapes or text."""
    h, w = shape
    kind = int(rng.integers(0, 6))
    if kind < 3:
        which = SAMPLE_IMAGES[int(rng.integers(len(SAMPLE_IMAGES)))]
        content = fit(_sample_image(which), shape)
    elif kind == 3:
        name, key = SAMPLE_ARRAYS[int(rng.integers(len(SAMPLE_ARRAYS)))]
        content = fit(_sample_array(name, key), shape)
    elif kind == 4:
        content = shapes_picture(rng, shape)
    else:
        content = blank(shape, float(rng.uniform(0.75, 0.95)))
        fill_rect(content, h // 12, w // 12, h // 4, w - w // 12, float(rng.uniform(0.1, 0.3)))
        text_lines(content, rng, (h // 3, w // 12, h - h // 12, w - w // 12), 0.1, 0.6)
    content = normalise(content, float(rng.uniform(0.03, 0.15)), float(rng.uniform(0.8, 0.97)))
    frame(content, 0, 0, h, w, max(2, min(h, w) // 30), float(rng.uniform(0.05, 0.3)))
    return content


def shapes_picture(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Random filled circles, rectangles and lines on a noisy background."""
    h, w = shape
    tex = 0.5 + 0.15 * noise(rng, shape, max(h, w) / 3)
    for _ in range(int(rng.integers(6, 16))):
        v = float(rng.uniform(0.0, 1.0))
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        size = int(rng.integers(max(2, min(h, w) // 12), max(3, min(h, w) // 3)))
        pick = rng.integers(3)
        if pick == 0:
            cv2.circle(tex, (x, y), size, v, -1, cv2.LINE_AA)
        elif pick == 1:
            cv2.rectangle(tex, (x, y), (x + size, y + int(size * rng.uniform(0.3, 2))), v, -1)
        else:
            x2, y2 = int(rng.integers(0, w)), int(rng.integers(0, h))
            cv2.line(tex, (x, y), (x2, y2), v, max(1, size // 6), cv2.LINE_AA)
    return tex


# --------------------------------------------------------------------------- wall fixtures


def door(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A panelled door with its frame and handle (frame included in ``shape``)."""
    h, w = shape
    leaf = float(rng.uniform(0.35, 0.7))
    tex = leaf + 0.05 * noise(rng, shape, w / 2)
    f = max(2, w // 14)
    frame(tex, 0, 0, h + f, w, f, float(np.clip(leaf + rng.choice([-0.25, 0.25]), 0.05, 0.95)))
    for r0, r1 in ((h // 10, h * 9 // 20), (h // 2, h * 9 // 10)):
        frame(tex, r0, w // 5, r1, w - w // 5, max(1, f // 2), leaf - 0.12)
    hr, hc = h * 53 // 100, w - w // 7
    fill_rect(tex, hr - f // 2, hc - 2 * f, hr + f // 2, hc, 0.9)
    fill_rect(tex, hr + f, hc - f // 2, hr + 2 * f, hc, 0.05)  # key hole
    return tex


def curtains_closed(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Drawn curtains: vertical folds over a faint woven pattern."""
    h, w = shape
    base = float(rng.uniform(0.4, 0.7))
    period = float(rng.uniform(6, 14))
    cols = np.arange(w, dtype=np.float32)
    folds = 0.12 * np.sin(2 * np.pi * cols / period + 0.8 * noise(rng, (1, w), w / 8)[0])
    tex = base + folds[None, :] + 0.04 * noise(rng, shape, 6, octaves=2)
    pattern_step = int(rng.integers(12, 30))
    tex[::pattern_step, :] -= 0.08
    return tex


def outside_view(rng: Rng, shape: tuple[int, int]) -> Texture:
    """The view through a window: bright sky, a tree line and buildings (relative luminance)."""
    h, w = shape
    tex = np.empty(shape, np.float32)
    tex[:] = np.linspace(1.0, 0.8, h, dtype=np.float32)[:, None]
    horizon = h * float(rng.uniform(0.45, 0.65))
    skyline = horizon + h * 0.2 * noise(rng, (1, w), w / 6)[0]
    rows = np.arange(h, dtype=np.float32)[:, None]
    trees = rows > skyline[None, :]
    tex[trees] = 0.25 + 0.1 * noise(rng, shape, 4)[trees]
    for _ in range(int(rng.integers(1, 4))):
        c0 = int(rng.integers(0, w))
        bw, top = int(rng.integers(w // 8, w // 3)), int(horizon - rng.uniform(0, h * 0.3))
        fill_rect(tex, top, c0, h, c0 + bw, float(rng.uniform(0.45, 0.7)))
        for r in range(top + 6, h - 4, 12):  # windows of the building
            for c in range(c0 + 4, c0 + bw - 6, 10):
                fill_rect(tex, r, c, r + 5, c + 5, 0.2)
    return tex


def window(rng: Rng, shape: tuple[int, int], frame_px: int) -> tuple[Texture, Texture, Texture]:
    """A window with sill: (albedo with curtains shut, albedo with them open, glow mask).

    The glow mask (0..1) is the relative luminance of the outside view where it shows through.
    """
    h, w = shape
    closed = curtains_closed(rng, shape)
    view = outside_view(rng, shape)
    opened = blank(shape, 0.0)
    glow = view.copy()
    side = w // 6
    fill_rect(opened, 0, 0, h, side, curtains_closed(rng, (h, side)))
    fill_rect(opened, 0, w - side, h, w, curtains_closed(rng, (h, side)))
    glow[:, :side] = 0.0
    glow[:, w - side :] = 0.0
    for tex in (closed, opened, glow):
        frame(tex, 0, 0, h, w, frame_px, 0.85 if tex is not glow else 0.0)
    bars = (w // 2, h // 2)
    fill_rect(opened, 0, bars[0] - frame_px // 2, h, bars[0] + frame_px // 2, 0.85)
    fill_rect(glow, 0, bars[0] - frame_px // 2, h, bars[0] + frame_px // 2, 0.0)
    return closed, opened, glow


def radiator(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A ribbed radiator: bright fins with dark gaps and a pipe."""
    h, w = shape
    tex = blank(shape, float(rng.uniform(0.75, 0.9)))
    period = int(rng.integers(4, 7))
    tex[:, ::period] = 0.35
    tex[:, 1::period] *= 0.8
    fill_rect(tex, 0, 0, max(2, h // 12), w, 0.95)
    fill_rect(tex, h - max(2, h // 12), 0, h, w, 0.5)
    return tex


def bookshelf(rng: Rng, shape: tuple[int, int], board_px: int) -> Texture:
    """Shelves with books of random widths, heights and greys, some with spine labels."""
    h, w = shape
    wood = float(rng.uniform(0.3, 0.6))
    tex = wood - 0.15 + 0.03 * noise(rng, shape, 20)
    n_boards = max(2, h // int(rng.integers(30, 40)))
    pitch = h / n_boards
    for k in range(n_boards):
        bottom = int((k + 1) * pitch)
        fill_rect(tex, bottom - board_px, 0, bottom, w, wood)
        c = board_px
        while c < w - board_px:
            bw = int(rng.integers(2, 7))
            bh = int(pitch * rng.uniform(0.5, 0.9))
            grey = float(rng.uniform(0.05, 0.95))
            fill_rect(tex, bottom - board_px - bh, c, bottom - board_px, c + bw, grey)
            if bw >= 4 and rng.random() < 0.5:
                label = 1.0 - grey
                fill_rect(
                    tex,
                    bottom - board_px - bh * 2 // 3,
                    c + 1,
                    bottom - board_px - bh // 2,
                    c + bw - 1,
                    label,
                )
            c += bw + int(rng.integers(0, 2))
            if rng.random() < 0.05:
                c += int(rng.integers(5, 20))
    frame(tex, 0, 0, h, w, board_px, wood)
    return tex


def whiteboard(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A whiteboard with scribbles, a diagram and text."""
    h, w = shape
    tex = blank(shape, 0.93)
    pts = rng.integers(0, [w, h], size=(int(rng.integers(3, 8)), 2)).astype(np.int32)
    cv2.polylines(tex, [pts], False, 0.15, 2, cv2.LINE_AA)
    for _ in range(int(rng.integers(2, 5))):
        c = rng.integers(0, [w, h])
        cv2.circle(
            tex, (int(c[0]), int(c[1])), int(rng.integers(5, max(6, h // 5))), 0.2, 2, cv2.LINE_AA
        )
    text_lines(tex, rng, (h // 10, w // 20, h - h // 10, w // 2), 0.15, 0.5)
    frame(tex, 0, 0, h, w, 3, 0.6)
    return tex


def clock(rng: Rng, size: int) -> Texture:
    """A round wall clock on a transparent-looking square (the wall shows as NaN)."""
    tex = blank((size, size), np.nan)
    c, r = size // 2, size // 2 - 1
    cv2.circle(tex, (c, c), r, 0.95, -1, cv2.LINE_AA)
    cv2.circle(tex, (c, c), r, 0.1, max(2, size // 15), cv2.LINE_AA)
    for k in range(12):
        a = k * np.pi / 6
        p1 = (int(c + 0.75 * r * np.cos(a)), int(c + 0.75 * r * np.sin(a)))
        p2 = (int(c + 0.88 * r * np.cos(a)), int(c + 0.88 * r * np.sin(a)))
        cv2.line(tex, p1, p2, 0.1, 2, cv2.LINE_AA)
    for length, a in ((0.5, rng.uniform(0, 2 * np.pi)), (0.8, rng.uniform(0, 2 * np.pi))):
        tip = (int(c + length * r * np.cos(a)), int(c + length * r * np.sin(a)))
        cv2.line(tex, (c, c), tip, 0.05, max(2, size // 20), cv2.LINE_AA)
    return tex


def notice_board(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A cork board covered with notes, some with text."""
    h, w = shape
    tex = 0.45 + 0.06 * noise(rng, shape, 2, octaves=2)
    for _ in range(int(h * w / 900) + 3):
        nh, nw = int(rng.integers(12, 30)), int(rng.integers(10, 24))
        r0, c0 = int(rng.integers(-5, h - 5)), int(rng.integers(-5, w - 5))
        grey = float(rng.uniform(0.6, 1.0))
        fill_rect(tex, r0, c0, r0 + nh, c0 + nw, grey)
        if rng.random() < 0.7:
            text_lines(tex, rng, (r0, c0, r0 + nh, c0 + nw + 20), 0.1, 0.25)
    frame(tex, 0, 0, h, w, 3, 0.3)
    return tex


def pipes(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Horizontal pipes and a cable tray (rows of light and dark bands); NaN = wall."""
    h, w = shape
    tex = blank(shape, np.nan)
    r = 0
    while r < h - 3:
        width = int(rng.integers(2, 7))
        grey = float(rng.uniform(0.3, 0.95))
        fill_rect(tex, r, 0, r + width, w, grey)
        fill_rect(tex, r + width - 1, 0, r + width, w, grey * 0.5)
        r += width + int(rng.integers(1, 6))
    for c in range(int(rng.integers(10, 40)), w, int(rng.integers(60, 140))):  # brackets
        fill_rect(tex, 0, c, h, c + 2, 0.2)
    return tex


def plain_wall(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Painted plaster: a base grey with blotches and fine grain."""
    base = float(rng.uniform(0.6, 0.8))
    return base + 0.04 * noise(rng, shape, 60) + 0.015 * noise(rng, shape, 2, octaves=1)


# --------------------------------------------------------------------------- floor and ceiling


def floor(rng: Rng, shape: tuple[int, int], px_per_m: float) -> Texture:
    """Floor tiles with grout and per-tile shade, or a patterned carpet."""
    h, w = shape
    if rng.random() < 0.5:
        tile = int(px_per_m * rng.uniform(0.3, 0.5))
        shades = rng.uniform(0.25, 0.6, size=(h // tile + 1, w // tile + 1)).astype(np.float32)
        tex = np.kron(shades, np.ones((tile, tile), np.float32))[:h, :w]
        tex = tex + 0.05 * noise(rng, shape, 8)
        tex[::tile, :] = 0.15
        tex[:, ::tile] = 0.15
    else:
        tex = 0.35 + 0.08 * noise(rng, shape, 40) + 0.05 * noise(rng, shape, 3, octaves=1)
        period = int(px_per_m * rng.uniform(0.15, 0.3))
        rows, cols = np.mgrid[0:h, 0:w]
        motif = ((rows // period + cols // period) % 2).astype(np.float32)
        tex = tex + 0.1 * motif
    for _ in range(int(rng.integers(1, 4))):  # rugs / stains
        c = rng.integers(0, [w, h])
        axes = (int(rng.integers(20, 80)), int(rng.integers(20, 80)))
        cv2.ellipse(
            tex,
            (int(c[0]), int(c[1])),
            axes,
            float(rng.uniform(0, 180)),
            0,
            360,
            float(rng.uniform(0.1, 0.7)),
            -1,
            cv2.LINE_AA,
        )
    return tex


def ceiling_tiles(rng: Rng, shape: tuple[int, int], px_per_m: float) -> Texture:
    """Acoustic ceiling tiles in a 0.6 m grid with speckle."""
    tex = 0.8 + 0.05 * noise(rng, shape, 3, octaves=2)
    step = int(0.6 * px_per_m)
    tex[::step, :] = 0.5
    tex[:, ::step] = 0.5
    return tex


# --------------------------------------------------------------------------- object materials


def wood(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Wood grain: stretched noise along the columns."""
    h, w = shape
    grain = noise(rng, (max(2, h // 8), w), 6)
    grain = cv2.resize(grain, (w, h), interpolation=cv2.INTER_LINEAR)
    return float(rng.uniform(0.35, 0.65)) + 0.08 * grain


def cabinet(rng: Rng, shape: tuple[int, int], front_cols: int) -> Texture:
    """A cabinet unrolled around its sides; the first ``front_cols`` columns are its front."""
    h, w = shape
    tex = wood(rng, shape) if rng.random() < 0.5 else metal(rng, shape)
    fc = max(4, front_cols)
    n_drawers = int(rng.integers(1, 5))
    edge = tex[0, 0] - 0.2
    for k in range(n_drawers):
        r0, r1 = h * k // n_drawers, h * (k + 1) // n_drawers
        frame(tex, r0, 0, r1, fc, 2, edge)
        hr = (r0 + r1) // 2 if n_drawers > 1 else h // 3
        fill_rect(tex, hr - 2, fc // 2 - 8, hr + 2, fc // 2 + 8, 0.05)
    if rng.random() < 0.6:
        label = (h // 8, fc // 4, h // 8 + max(6, h // 10), fc * 3 // 4)
        fill_rect(tex, *label, 0.95)
        text_lines(tex, rng, label, 0.05, 0.35)
    return tex


def metal(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Painted sheet metal with faint vertical streaks."""
    h, w = shape
    streak = noise(rng, (1, w), 3)[0]
    return float(rng.uniform(0.45, 0.85)) + 0.03 * streak[None, :] + np.zeros(shape, np.float32)


def cardboard(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Cardboard with tape, a printed label and arrows."""
    h, w = shape
    tex = float(rng.uniform(0.45, 0.65)) + 0.04 * noise(rng, shape, 10)
    fill_rect(tex, 0, w // 2 - 3, h // 5, w // 2 + 3, 0.8)
    for c0 in range(0, w, max(8, w // 4)):
        r0 = int(rng.integers(h // 4, max(h // 4 + 1, h - 20)))
        if rng.random() < 0.5:
            fill_rect(tex, r0, c0 + 4, r0 + 14, c0 + 30, 0.95)
            text_lines(tex, rng, (r0, c0 + 4, r0 + 14, c0 + 40), 0.05, 0.3)
        else:
            tip = (c0 + 10, r0)
            cv2.arrowedLine(tex, (c0 + 10, r0 + 20), tip, 0.1, 2, cv2.LINE_AA, tipLength=0.4)
    return tex


def striped(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Plastic with horizontal bands and vertical ribs (bins, pots)."""
    h, w = shape
    tex = blank(shape, float(rng.uniform(0.2, 0.8)))
    tex[:, :: int(rng.integers(5, 12))] -= 0.12
    for _ in range(int(rng.integers(1, 3))):
        r0 = int(rng.integers(0, max(1, h - 6)))
        fill_rect(tex, r0, 0, r0 + int(rng.integers(3, 8)), w, float(rng.uniform(0, 1)))
    return tex


def foliage(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Dense leaves: many overlapping ellipses in dark to light greys."""
    h, w = shape
    tex = 0.12 + 0.05 * noise(rng, shape, 6)
    n = int(h * w / 40) + 10
    centres = rng.integers(0, [w, h], size=(n, 2))
    sizes = rng.integers(3, 9, size=(n, 2))
    angles = rng.uniform(0, 180, size=n)
    greys = rng.uniform(0.1, 0.7, size=n)
    for (x, y), (a, b), ang, g in zip(centres, sizes, angles, greys, strict=True):
        cv2.ellipse(
            tex,
            (int(x), int(y)),
            (int(a), int(b // 2 + 1)),
            float(ang),
            0,
            360,
            float(g),
            -1,
            cv2.LINE_AA,
        )
    return tex


def bark(rng: Rng, shape: tuple[int, int]) -> Texture:
    h, w = shape
    streaks = cv2.resize(noise(rng, (max(2, h // 10), w), 2), (w, h))
    return 0.25 + 0.08 * streaks


def fabric(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Upholstery: a woven check pattern with a random base grey."""
    h, w = shape
    rows, cols = np.mgrid[0:h, 0:w]
    period = int(rng.integers(3, 8))
    check = (((rows // period) + (cols // period)) % 2).astype(np.float32)
    return float(rng.uniform(0.15, 0.7)) + 0.1 * check + 0.03 * noise(rng, shape, 4)


def checker(
    shape: tuple[int, int], squares: tuple[int, int], low: float = 0.05, high: float = 0.95
) -> Texture:
    """A checkerboard of ``squares`` = (rows, cols) cells (marker objects)."""
    h, w = shape
    rows = (np.arange(h) * squares[0] // h)[:, None]
    cols = (np.arange(w) * squares[1] // w)[None, :]
    return np.where((rows + cols) % 2 == 0, high, low).astype(np.float32)
