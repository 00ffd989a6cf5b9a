"""Plots for paper: the scope draws light traces on a dark background, which prints as a dark
block with an unreadable legend. For the report the picture's lightness is turned over while each
colour keeps its hue and saturation: the background becomes white, white grid lines and text black,
and a yellow trace a darker yellow that reads on paper."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QBuffer, QIODevice
from PySide6.QtGui import QImage, QImageWriter

from fha_studio import fileio


def for_paper(image: QImage) -> QImage:
    """``image`` with its HSL lightness inverted, hue and saturation kept (a new image), when it
    is mostly dark; a picture that is light already (a plot on white) is returned as it is.

    In RGB that is ``c + (1 - max - min)`` for each channel: an inversion (``1 - c``) followed by
    a half turn of the hue (``max + min - c``)."""
    rgb = image.convertToFormat(QImage.Format.Format_RGB888)
    width, height, stride = rgb.width(), rgb.height(), rgb.bytesPerLine()
    buffer = np.frombuffer(rgb.constBits(), dtype=np.uint8, count=stride * height)
    pixels = buffer.reshape(height, stride)[:, : width * 3].reshape(height, width, 3).astype(np.int16)
    lightness_x2 = pixels.max(axis=2, keepdims=True) + pixels.min(axis=2, keepdims=True)
    if np.median(lightness_x2) >= 255:  # a light background: fit for paper as it is
        return rgb.copy()
    shift = 255 - lightness_x2
    turned = np.ascontiguousarray(np.clip(pixels + shift, 0, 255).astype(np.uint8))
    out = QImage(turned.data, width, height, width * 3, QImage.Format.Format_RGB888)
    return out.copy()  # own the pixels: ``turned`` goes away with this function


def save_for_paper(png_path: str | Path) -> Path:
    """Rewrite the PNG at ``png_path`` for paper (see :func:`for_paper`), whole or not at all
    (:func:`fileio.write_bytes`); returns the path."""
    path = Path(png_path)
    image = QImage(str(path))
    if image.isNull():
        raise ValueError(f"{path}: not an image FHA Studio can read")
    buffer = QBuffer()
    buffer.open(QIODevice.OpenModeFlag.WriteOnly)
    writer = QImageWriter(buffer, b"PNG")
    if not writer.write(for_paper(image)):
        raise OSError(f"{path}: could not be turned into a PNG ({writer.errorString()})")
    fileio.write_bytes(path, bytes(buffer.data().data()))
    return path


__all__ = ["for_paper", "save_for_paper"]
