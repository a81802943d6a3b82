"""The Python API: loading, rendering, writing, plugins, errors, interruption, chi-square."""

import os
import signal
import subprocess
import threading
import time

import numpy as np
import pytest

import facet

SMALL = dict(res=48, spp=8, max_depth=4)


def test_render_matches_cli_exr(cornell, facet_cli, cli_env, tmp_path):
    """The array facet.render returns is the image `facet render` writes: same pixels after the
    film's float16 rounding, same channels."""
    scene = facet.load_file(cornell, **SMALL)
    image = facet.render(scene, seed=3, threads=2)
    pixels, channels = image
    assert pixels.dtype == np.float32 and pixels.shape == (48, 48, 3)
    assert channels == ["R", "G", "B"]
    assert image.half  # hdrfilm's default component_format is float16
    assert pixels.mean() > 0.05  # the box is lit

    out = tmp_path / "cli.exr"
    cmd = [str(facet_cli), "render", str(cornell), "-q", "--seed", "3", "-t", "1", "-o", str(out)]
    cmd += [f"-D{k}={v}" for k, v in SMALL.items()]
    subprocess.run(cmd, check=True, env=cli_env)
    cli_pixels, cli_channels = facet.read(out)
    assert cli_channels == channels
    assert np.array_equal(pixels.astype(np.float16).astype(np.float32), cli_pixels)

    # facet.write goes through the same writer: the file is the CLI's, pixel for pixel.
    mine = tmp_path / "py.exr"
    facet.write(image, mine)
    assert np.array_equal(facet.read(mine)[0], cli_pixels)


def test_render_is_deterministic_and_seeded(cornell):
    scene = facet.load_file(cornell, **SMALL)
    a = facet.render(scene, seed=1, threads=1).pixels
    b = facet.render(scene, seed=1, threads=2).pixels
    c = facet.render(scene, seed=2, threads=2).pixels
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_spp_override_and_metadata(cornell):
    scene = facet.load_file(cornell, **SMALL)
    image = facet.render(scene, spp=2, seed=5)
    assert image.metadata["facet:spp"] == "2"
    assert image.metadata["facet:seed"] == "5"
    assert image.metadata["facet:scene"] == str(cornell.resolve())


def test_aov_channels(tmp_path):
    xml = """<scene version="3.0.0">
        <integrator type="aov"><string name="aovs" value="dd:depth, nn:sh_normal"/></integrator>
        <sensor type="orthographic">
            <transform name="to_world"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
            <film type="hdrfilm"><integer name="width" value="$w"/><integer name="height" value="6"/>
                <rfilter type="box"/></film>
        </sensor>
        <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform></shape>
    </scene>"""
    pixels, channels = facet.render(facet.load_string(xml, w=8))
    assert pixels.shape == (6, 8, len(channels))
    assert channels[:3] == ["R", "G", "B"]
    assert "dd.Y" in channels or any(c.startswith("dd") for c in channels)
    depth = pixels[..., [i for i, c in enumerate(channels) if c.startswith("dd")][0]]
    np.testing.assert_allclose(depth, 5.0, rtol=1e-5)  # the plane z = 0 seen from z = 5
    path = tmp_path / "aov.exr"
    facet.write((pixels, channels), path)
    back, back_channels = facet.read(path)
    assert back_channels == channels
    assert np.array_equal(back, pixels)  # written as float32: no film, no float16


def test_write_png_and_plain_array(tmp_path):
    img = np.full((4, 5, 3), 0.5, dtype=np.float32)
    facet.write(img, tmp_path / "a.png")
    px, ch = facet.read(tmp_path / "a.png")
    assert px.shape == (4, 5, 3)
    assert 0.6 < px.mean() < 0.9  # sRGB-encoded 0.5, read back as stored
    with pytest.raises(facet.Error, match="no image format"):
        facet.write(img, tmp_path / "a.notaformat")


def test_errors_carry_the_scene_location(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <bsdf type="difuse"/>\n</scene>\n')
    with pytest.raises(facet.Error) as info:
        facet.load_file(bad)
    assert f"{bad}:2:" in str(info.value)
    assert "diffuse" in str(info.value)  # the suggestion
    assert info.value.file == str(bad) and info.value.line == 2
    assert isinstance(info.value, RuntimeError)

    with pytest.raises(facet.Error, match=r"string:1:\d+"):
        facet.load_string('<scene version="3.0.0"><float name="x" value="1"/><bsdf type="nope"/></scene>')
    with pytest.raises(facet.Error, match="does not exist"):
        facet.load_file(tmp_path / "missing.xml")
    with pytest.raises(facet.Error, match="never used|unused|not used"):
        facet.load_file(cornell_path(), not_a_parameter=3)
    scene = facet.load_file(cornell_path(), **SMALL)
    with pytest.raises(facet.Error, match="sensor 2"):
        facet.render(scene, sensor=2)
    with pytest.raises(facet.Error, match="spp=0"):
        facet.render(scene, spp=0)


def cornell_path():
    from conftest import CORNELL

    return CORNELL


def test_plugins():
    plugins = facet.plugins()
    names = {p.name for p in plugins}
    assert {"diffuse", "path", "hdrfilm", "perspective", "area"} <= names
    bsdfs = facet.plugins("bsdf")
    assert bsdfs and all(p.kind == "bsdf" for p in bsdfs)
    diffuse = next(p for p in bsdfs if p.name == "diffuse")
    assert "reflectance" in diffuse.doc and diffuse.description


def test_ctrl_c_stops_the_render(cornell):
    """SIGINT during a render stops it (RenderOptions::cancel) and raises KeyboardInterrupt,
    promptly: well before the render would have finished."""
    # 400 blocks of 32 x 32 pixels x 256 samples: minutes of work on 2 threads, a block well
    # under a second.
    scene = facet.load_file(cornell, res=640, spp=256)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        facet.render(scene, threads=2)
    elapsed = time.monotonic() - start
    timer.join()
    assert elapsed < 15.0, f"the render went on for {elapsed:.1f} s after Ctrl-C"
    # The scene is still usable afterwards.
    assert facet.render(facet.load_file(cornell, **SMALL)).pixels.shape == (48, 48, 3)


def test_ctrl_c_raises_promptly_with_the_partial_image(cornell):
    """The KeyboardInterrupt of a stopped render carries the passes done as `partial`, a
    facet.Image like the one render() returns (what `facet render` writes on Ctrl-C), and comes
    within a second of the signal."""
    scene = facet.load_file(cornell, res=64, spp=100000, max_depth=4)
    sent = []

    def ctrl_c():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(1.0, ctrl_c)
    timer.start()
    with pytest.raises(KeyboardInterrupt) as info:
        facet.render(scene, threads=2)
    raised = time.monotonic()
    timer.join()
    assert raised - sent[0] < 1.0, f"KeyboardInterrupt {raised - sent[0]:.2f} s after Ctrl-C"
    partial = info.value.partial
    assert isinstance(partial, facet.Image)
    assert partial.pixels.shape == (64, 64, 3)
    assert partial.channels == ["R", "G", "B"]
    spp = int(partial.metadata["facet:spp"])
    assert 1 <= spp < 100000
    assert partial.metadata["facet:spp_target"] == "100000"
    assert "facet:blocks" in partial.metadata
    assert np.isfinite(partial.pixels).all() and partial.pixels.mean() > 0.0


def test_render_releases_the_gil(cornell):
    """Python code runs while a render is in progress on another thread: with the GIL held for
    the whole render, this loop could not run until the render returned."""
    scene = facet.load_file(cornell, res=96, spp=64)
    started = threading.Event()

    def work():
        started.set()
        facet.render(scene, threads=1)

    t = threading.Thread(target=work)
    start = time.monotonic()
    t.start()
    started.wait()
    iterations = 0
    while t.is_alive():
        iterations += 1
        time.sleep(0.001)
    t.join()
    assert time.monotonic() - start > 0.3, "render too fast to tell"
    assert iterations >= 50, f"only {iterations} iterations ran during the render"


def test_chi2_accepts_and_rejects():
    good = facet.chi2("bsdf", "roughconductor", distribution="ggx", alpha=0.3, theta=50,
                      samples=200000, res=16)
    assert good.passed, good.summary()
    assert good.observed.shape == (16, 32) and good.expected.shape == (16, 32)
    assert good.observed.sum() == pytest.approx(good.samples * good.pdf_integral, rel=0.02)
    assert 0.0 < good.p_value <= 1.0 and good.dof > 0 and good.statistic > 0.0

    micro = facet.chi2("microfacet", "beckmann", alpha=0.2, theta=40, samples=100000, res=16)
    assert micro.passed, micro.summary()

    emitter = facet.chi2("emitter", "area", shape="sphere", samples=100000, res=16)
    assert emitter.passed, emitter.summary()

    # A sampler that does not match its pdf is rejected (the chi-square suite's test plugin).
    from conftest import BINARY_DIR

    facet.add_plugin_dir(BINARY_DIR / "tests" / "chi2_plugins")
    bad = facet.chi2("bsdf", "chi2_lambert_bug", bug="uniform", samples=200000, res=16)
    assert not bad.passed
    assert bad.p_value < bad.significance
    assert np.abs(bad.observed - bad.expected).max() > 100

    with pytest.raises(facet.Error, match="alhpa"):
        facet.chi2("bsdf", "roughconductor", alhpa=0.3, samples=1000)
    with pytest.raises(ValueError):
        facet.chi2("shape", "sphere")
