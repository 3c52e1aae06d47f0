"""Reading colours out of rendered frames (shared by the Viewer's tests)."""
import numpy as np


def pixel(frame: np.ndarray, uv) -> np.ndarray:
    """RGB at pixel coordinates (column, row) as Camera.project gives them."""
    u, v = uv
    return frame[int(v), int(u)].astype(int)


def patch(frame: np.ndarray, uv, half: int = 2) -> np.ndarray:
    """Mean RGB of a (2 half + 1)^2 patch around (column, row)."""
    u, v = int(uv[0]), int(uv[1])
    return frame[v - half:v + half + 1, u - half:u + half + 1].reshape(-1, 3).mean(axis=0)


def is_hue(rgb, channel: int) -> bool:
    """The pixel is clearly of one primary colour (0 red, 1 green, 2 blue): that channel is
    bright and the others at most a third of it."""
    rgb = np.asarray(rgb, dtype=float)
    others = np.delete(rgb, channel)
    return rgb[channel] > 80 and np.all(others < rgb[channel] / 3)


def is_grey(rgb, background) -> bool:
    """Neutral grey, and darker than the (light) background."""
    rgb = np.asarray(rgb, dtype=float)
    return rgb.max() - rgb.min() < 10 and rgb.mean() < np.mean(background) * 255 - 60


def is_background(rgb, background) -> bool:
    return np.all(np.abs(np.asarray(rgb, float) - np.asarray(background) * 255) < 6)
