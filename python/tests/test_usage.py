"""Python as people use it: the image as an array, progress, display/view/look on write, scene
info without loading, and the README's examples run as scripts."""

import os
import pty
import re
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import facet

from conftest import BINARY_DIR, SOURCE_DIR

SMALL = dict(res=32, spp=4, max_depth=3)
STUDIO = SOURCE_DIR / "tests" / "data" / "ocio" / "studio.config"


def test_image_is_an_array_with_channel_names(cornell):
    image = facet.render(facet.load_file(cornell, **SMALL), seed=1)
    pixels = np.asarray(image)
    assert pixels.dtype == np.float32 and pixels.shape == (32, 32, 3)
    assert image.channels == ["R", "G", "B"]
    assert np.array_equal(pixels, image.pixels)
    assert np.asarray(image, dtype=np.float64).dtype == np.float64
    assert (np.asarray(image) * 2).shape == (32, 32, 3)
    # The pair form still unpacks.
    px, ch = image
    assert px is image.pixels and ch == ["R", "G", "B"]


def test_progress_callback_rises_to_one(cornell):
    scene = facet.load_file(cornell, res=96, spp=64, max_depth=4)
    seen = []
    facet.render(scene, threads=1, progress=seen.append)
    assert seen and seen[-1] == 1.0
    assert all(0.0 <= a <= b <= 1.0 for a, b in zip(seen, seen[1:])), seen
    # The whole of a render of several passes, not each pass from 0 again.
    seen.clear()
    facet.render(facet.load_file(cornell, **SMALL), passes=3, progress=seen.append)
    assert seen[-1] == 1.0 and seen == sorted(seen)


def test_progress_callback_that_raises_stops_the_render(cornell):
    scene = facet.load_file(cornell, res=640, spp=256)

    def stop(fraction):
        raise ValueError("enough")

    start = time.monotonic()
    with pytest.raises(ValueError, match="enough"):
        facet.render(scene, threads=2, progress=stop)
    assert time.monotonic() - start < 15.0


def _stderr_through_a_terminal(code):
    """Runs `code` in a fresh interpreter whose stderr is a terminal; returns what it printed."""
    master, slave = pty.openpty()
    env = dict(os.environ)
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=slave, stdout=subprocess.DEVNULL,
                            env=env)
    os.close(slave)
    out = b""
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:
            break
        if not chunk:
            break
        out += chunk
    proc.wait(timeout=120)
    os.close(master)
    assert proc.returncode == 0, out
    return out.decode(errors="replace")


def test_progress_bar_on_a_terminal(cornell):
    load = f"import facet; s = facet.load_file({str(cornell)!r}, res=48, spp=8, max_depth=3)\n"
    assert "Rendering [" in _stderr_through_a_terminal(load + "facet.render(s)")
    assert "Rendering [" not in _stderr_through_a_terminal(load + "facet.render(s, progress=False)")


def test_write_takes_display_view_and_look(tmp_path):
    """Any config the CLI takes: the test config has no view "Standard"."""
    img = np.full((2, 2, 3), 0.25, dtype=np.float32)

    def code(**kwargs):
        path = tmp_path / "x.png"
        facet.write(img, path, ocio_config=STUDIO, **kwargs)
        return int(round(facet.read(path)[0][0, 0, 0] * 255))

    assert code() == 128  # Studio Monitor / Film: 0.25^(1/2)
    assert code(view="Linear") == 64
    assert code(look="push") == 180  # x2 before the view
    assert code(display="Projector") == 64
    with pytest.raises(facet.Error, match='no view "Standard"'):
        code(view="Standard")
    # facet's own config still defaults to its sRGB display and Standard view.
    facet.write(img, tmp_path / "own.png")
    assert 0.5 < facet.read(tmp_path / "own.png")[0].mean() < 0.6
