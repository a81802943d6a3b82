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


def test_scene_info_parses_without_loading(cornell, tmp_path):
    info = facet.scene_info(cornell, res=100)
    assert info["sensors"][0]["film_size"] == (100, 100)
    assert info["sensors"][0]["spp"] == 64
    assert info["mode"] == "scalar_rgb"
    assert "diffuse" in info["plugins"]["bsdf"]
    # A mesh that does not exist is not read: parsing alone does not need it.
    xml = tmp_path / "mesh.xml"
    xml.write_text('<scene version="3.0.0"><shape type="ply"><string name="filename" '
                   'value="missing.ply"/></shape><sensor type="thinlens"><film type="hdrfilm">'
                   '<integer name="width" value="$w"/></film></sensor></scene>')
    info = facet.scene_info(xml, w=33)
    assert info["sensors"] == [dict(plugin="thinlens", film="hdrfilm", sampler="independent",
                                    film_size=(33, 576), spp=4)]
    with pytest.raises(facet.Error):
        facet.load_file(xml, w=33)


def _readme_block(after):
    """The first ```python block after the line `after` in README.md."""
    text = (SOURCE_DIR / "README.md").read_text()
    start = text.index(after)
    m = re.search(r"```python\n(.*?)```", text[start:], re.S)
    assert m, f"no python block after {after!r}"
    return m.group(1)


def test_readme_dask_example_runs_as_a_script(tmp_path):
    """Saved as a file and run, the README's example finishes (worker processes import the main
    module: without the __main__ guard each would start a cluster of its own)."""
    pytest.importorskip("distributed")
    script = tmp_path / "dask_example.py"
    script.write_text(_readme_block("### Dask"))
    assert 'if __name__ == "__main__":' in script.read_text()
    (tmp_path / "scenes").symlink_to(SOURCE_DIR / "scenes")
    subprocess.run([sys.executable, str(script)], cwd=tmp_path, check=True, timeout=300)
    pixels, channels = facet.read(tmp_path / "cornell.exr")
    assert channels == ["R", "G", "B"] and pixels.mean() > 0.05


def test_dask_tasks_take_the_workers_threads(cornell, monkeypatch):
    distributed = pytest.importorskip("distributed")
    import facet.distributed

    asked = []
    real = facet.render

    def spy(*args, **kwargs):
        asked.append(kwargs.get("threads"))
        return real(*args, **kwargs)

    monkeypatch.setattr(facet, "render", spy)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None, silence_logs=40) as cluster, \
            distributed.Client(cluster) as client:
        facet.distributed.render(cornell, client, tiles=(2, 1), params=SMALL)
        assert asked == [1, 1]
        asked.clear()
        facet.distributed.render(cornell, client, tiles=(2, 1), params=SMALL, threads=2)
        assert asked == [2, 2]
    assert facet.distributed._worker_threads() is None  # outside a worker: every core


def test_cli_info_prints_what_the_scene_declares(cornell, facet_cli, cli_env):
    out = subprocess.run([str(facet_cli), "info", str(cornell), "-D", "res=100"], env=cli_env,
                         check=True, capture_output=True, text=True).stdout
    assert "mode: scalar_rgb" in out
    assert "film: 100 x 100" in out
    assert "spp: 64" in out
    assert re.search(r"bsdf: .*diffuse", out), out
    size = subprocess.run([str(facet_cli), "info", str(cornell), "--film-size", "-D", "res=40"],
                          env=cli_env, check=True, capture_output=True, text=True).stdout
    assert size == "40 40\n"
    bad = subprocess.run([str(facet_cli), "info", str(cornell), "-D", "rez=4"], env=cli_env,
                         capture_output=True, text=True)
    assert bad.returncode != 0 and "rez" in bad.stderr


@pytest.mark.parametrize("columns", [30, 50, 69, 120])
def test_cli_progress_line_fits_the_terminal(cornell, facet_cli, cli_env, tmp_path, columns):
    import fcntl
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    cmd = [str(facet_cli), "render", str(cornell), "-D", "res=64", "-D", "spp=16", "-t", "1",
           "-o", str(tmp_path / "x.exr")]
    proc = subprocess.Popen(cmd, stderr=slave, stdout=subprocess.DEVNULL, env=cli_env)
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
    assert proc.wait(timeout=120) == 0
    os.close(master)
    text = out.decode()
    frames = [f for line in text.split("\n") for f in line.split("\r") if "Rendering" in f]
    assert frames, text
    for f in frames:
        assert len(f.rstrip("\r\n")) < columns, (columns, f)
    assert any("100%" in f for f in frames), frames
    if columns >= 69:
        assert any("[" in f for f in frames)  # room for a bar


def test_cli_suggests_the_nearest_define_and_option(cornell, facet_cli, cli_env, tmp_path):
    def error(*args):
        r = subprocess.run([str(facet_cli), *args], env=cli_env, capture_output=True, text=True)
        assert r.returncode != 0
        return r.stderr

    msg = error("render", str(cornell), "-D", "rez=4", "-o", str(tmp_path / "x.exr"))
    assert 'unused parameter "rez" (did you mean "res"?)' in msg, msg
    msg = error("render", str(cornell), "--seeed", "3", "-o", str(tmp_path / "x.exr"))
    assert 'did you mean "--seed"?' in msg, msg
    msg = error("info", str(cornell), "--film-sise")
    assert 'did you mean "--film-size"?' in msg, msg


def test_cli_announces_a_user_plugin_that_shadows_a_built_in(cornell, facet_cli, cli_env,
                                                             tmp_path):
    import shutil

    builtin = BINARY_DIR / "lib" / "facet" / "plugins" / "diffuse.so"
    assert builtin.exists(), builtin
    mine = tmp_path / "mine"
    mine.mkdir()
    shutil.copy(builtin, mine / "diffuse.so")
    r = subprocess.run([str(facet_cli), "render", str(cornell), "-a", str(mine), "-D", "res=16",
                        "-D", "spp=1", "-o", str(tmp_path / "x.exr")], env=cli_env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    lines = [l for l in r.stderr.splitlines() if "shadows the built-in" in l]
    assert len(lines) == 1 and str(mine / "diffuse.so") in lines[0], r.stderr
    listing = subprocess.run([str(facet_cli), "plugins", "bsdf", "-a", str(mine)], env=cli_env,
                             check=True, capture_output=True, text=True).stdout
    line = next(l for l in listing.splitlines() if l.strip().startswith("diffuse "))
    assert f"[{mine / 'diffuse.so'} (shadows the built-in)]" in line, listing
    other = next(l for l in listing.splitlines() if l.strip().startswith("conductor "))
    assert "[" not in other  # facet's own plugins are not annotated


COMPARE_SCENE = """<scene version="3.0.0">
    {integrator}
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0,0,4" target="0,0,0" up="0,1,0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
        <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="24"/>
            <rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle"><bsdf type="diffuse"/></shape>
    <shape type="sphere"><point name="center" value="0.3,0.2,1"/><float name="radius" value="0.3"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.6,0.3"/></bsdf></shape>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
</scene>"""


def test_cli_compare_with_a_moment_reference(facet_cli, cli_env, tmp_path):
    """The README's recipe: a reference rendered with the moment integrator gives `facet
    compare` both the mean and the per-sample variance."""
    path = '<integrator type="path"><integer name="max_depth" value="3"/></integrator>'
    (tmp_path / "scene.xml").write_text(COMPARE_SCENE.format(integrator=path))
    (tmp_path / "ref.xml").write_text(COMPARE_SCENE.format(
        integrator=f'<integrator type="moment">{path}</integrator>'))

    def run(*args, check=True):
        return subprocess.run([str(facet_cli), *map(str, args)], env=cli_env, check=check,
                              capture_output=True, text=True)

    run("render", tmp_path / "ref.xml", "-D", "spp=512", "-q", "-o", tmp_path / "ref.exr")
    run("render", tmp_path / "scene.xml", "-D", "spp=16", "--seed", "7", "-q", "-o",
        tmp_path / "ours.exr")
    ok = run("compare", tmp_path / "ours.exr", tmp_path / "ref.exr", "--spp", "16", check=False)
    assert ok.returncode == 0 and "PASS" in ok.stdout, ok.stdout + ok.stderr
    # A render 30% too bright does not agree.
    pixels, channels = facet.read(tmp_path / "ours.exr")
    facet.write((pixels * 1.3, channels), tmp_path / "bright.exr")
    bad = run("compare", tmp_path / "bright.exr", tmp_path / "ref.exr", "--spp", "16", check=False)
    assert bad.returncode == 1 and "FAIL" in bad.stdout, bad.stdout + bad.stderr
    # A plain render is no variance reference: the error says what to do.
    plain = run("compare", tmp_path / "ours.exr", tmp_path / "ours.exr", "--spp", "16",
                check=False)
    assert plain.returncode != 0 and "moment integrator" in plain.stderr, plain.stderr


def test_cli_output_into_a_folder(cornell, facet_cli, cli_env, tmp_path):
    out = tmp_path / "renders"
    out.mkdir()
    subprocess.run([str(facet_cli), "render", str(cornell), "-D", "res=8", "-D", "spp=1", "-q",
                    "-o", str(out)], env=cli_env, check=True)
    assert [p.name for p in out.iterdir()] == ["scene.exr"]
