"""The colour mode by Mitsuba's variant names: facet.modes(), facet.render(mode=...) and the
same answers as `facet render -m`."""

import subprocess

import numpy as np
import pytest

import facet

SMALL = dict(res=16, spp=2, max_depth=2)


@pytest.fixture
def scene(cornell):
    return facet.load_file(cornell, **SMALL)


def test_modes_lists_the_default_first():
    assert facet.modes() == [
        "scalar_rgb", "scalar_mono", "scalar_spectral", "scalar_spectral_polarized"]


def test_scalar_rgb_is_the_default(scene):
    plain = facet.render(scene, seed=1, progress=False)
    moded = facet.render(scene, seed=1, progress=False, mode="scalar_rgb")
    assert np.array_equal(np.asarray(plain), np.asarray(moded))
    assert plain.metadata["facet:mode"] == "scalar_rgb"
    assert moded.metadata["facet:mode"] == "scalar_rgb"


def test_vectorised_name_renders_as_scalar_rgb_with_one_note(scene, capfd):
    facet.set_log_level("info")  # the default: the note is at level info
    capfd.readouterr()
    plain = facet.render(scene, seed=1, progress=False)
    plain_err = capfd.readouterr().err
    image = facet.render(scene, seed=1, progress=False, mode="llvm_ad_rgb")
    err = capfd.readouterr().err
    # One line more than without a mode: the note.
    assert err.splitlines() == ['[I] mode "llvm_ad_rgb": facet renders it as scalar_rgb (facet '
                                'has no vectorised or differentiable modes)',
                                *plain_err.splitlines()]
    assert np.array_equal(np.asarray(plain), np.asarray(image))
    assert image.metadata["facet:mode"] == "scalar_rgb"


@pytest.mark.parametrize("mode", ["scalar_rgb_polarized", "cuda_mono_polarized", "foo",
                                  "scalar_rbg"])
def test_errors_are_those_of_the_cli(scene, cornell, facet_cli, cli_env, mode):
    with pytest.raises(facet.Error) as raised:
        facet.render(scene, progress=False, mode=mode)
    cli = subprocess.run([str(facet_cli), "render", str(cornell), "-m", mode], env=cli_env,
                         capture_output=True, text=True)
    assert cli.returncode != 0
    assert cli.stderr == f"facet: error: {raised.value}\n"
    assert "the modes" in str(raised.value) and "scalar_rgb" in str(raised.value)


def test_mode_must_be_a_string(scene):
    with pytest.raises(TypeError, match="mode=3"):
        facet.render(scene, progress=False, mode=3)


def test_scene_info_names_the_mode(cornell):
    assert facet.scene_info(cornell)["mode"] == facet.modes()[0]


@pytest.fixture
def mono(cornell):
    return facet.load_file(cornell, mode="scalar_mono", **SMALL)


def test_a_scene_renders_in_the_mode_it_was_loaded_in(scene, mono):
    assert scene.mode == "scalar_rgb" and mono.mode == "scalar_mono"
    image = facet.render(mono, seed=1, progress=False)
    assert image.metadata["facet:mode"] == "scalar_mono"
    pixels = np.asarray(image)
    # Mono: every channel holds the luminance. The Cornell box's red and green walls make an rgb
    # render's channels differ.
    assert np.array_equal(pixels[..., 0], pixels[..., 1])
    assert np.array_equal(pixels[..., 0], pixels[..., 2])
    assert pixels[..., 0].max() > 0
    rgb = np.asarray(facet.render(scene, seed=1, progress=False))
    assert not np.array_equal(rgb[..., 0], rgb[..., 1])
    # Same as naming the mode, and as the vectorised name of it.
    assert np.array_equal(pixels, np.asarray(facet.render(mono, seed=1, progress=False,
                                                          mode="scalar_mono")))
    assert np.array_equal(pixels, np.asarray(facet.render(mono, seed=1, progress=False,
                                                          mode="llvm_ad_mono")))


def test_the_cli_renders_the_same_mono_image(mono, cornell, facet_cli, cli_env, tmp_path):
    out = tmp_path / "mono.exr"
    args = [str(facet_cli), "render", str(cornell), "-m", "scalar_mono", "--seed", "1", "-q",
            "-o", str(out)] + [f"-D{k}={v}" for k, v in SMALL.items()]
    subprocess.run(args, env=cli_env, check=True)
    pixels, channels = facet.read(out)
    image = np.asarray(facet.render(mono, seed=1, progress=False))  # the film's float16 below
    assert np.array_equal(pixels[..., :3], image[..., :3].astype(np.float16).astype(np.float32))


def test_rendering_in_another_mode_than_the_loaded_one_is_an_error(scene, mono, capfd):
    with pytest.raises(facet.Error, match='the scene was loaded in scalar_rgb; load it with '
                                          'mode="scalar_mono"'):
        facet.render(scene, progress=False, mode="scalar_mono")
    facet.set_log_level("info")
    capfd.readouterr()
    with pytest.raises(facet.Error, match='loaded in scalar_mono; load it with mode="scalar_rgb"'):
        facet.render(mono, progress=False, mode="cuda_rgb")
    # The vectorised name's note, once.
    assert capfd.readouterr().err.count("facet renders it as scalar_rgb") == 1


def test_every_loader_takes_the_mode(cornell):
    assert facet.load_string(open(cornell).read(), search_path=[cornell.parent],
                             mode="scalar_mono", **SMALL).mode == "scalar_mono"
    d = {"type": "scene", "ball": {"type": "sphere"}}
    assert facet.load_dict(d, mode="scalar_mono").mode == "scalar_mono"
    assert facet.load_dict(d).mode == "scalar_rgb"
    assert facet.scene_info(cornell, mode="llvm_mono")["mode"] == "scalar_mono"
    with pytest.raises(facet.Error, match="scalar_rgb, scalar_mono, scalar_spectral"):
        facet.load_file(cornell, mode="scalar_rgb_polarized")
    with pytest.raises(TypeError, match="mode=1"):
        facet.load_file(cornell, mode=1)


def test_chi2_builds_the_plugin_in_a_colour_mode():
    args = dict(diffuse_reflectance=(0.9, 0.1, 0.1), alpha=0.25, theta=40, samples=100000, res=16)
    rgb = facet.chi2("bsdf", "roughplastic", **args)
    mono = facet.chi2("bsdf", "roughplastic", colour_mode="scalar_mono", **args)
    assert rgb.passed and mono.passed
    # The lobe weights come from the colour: the luminance of (0.9, 0.1, 0.1) is not its mean,
    # so the two draw different histograms from the same samples.
    assert not np.array_equal(rgb.observed, mono.observed)
    with pytest.raises(facet.Error, match="scalar_rgb, scalar_mono, scalar_spectral"):
        facet.chi2("bsdf", "diffuse", colour_mode="scalar_rgb_polarized")
    with pytest.raises(TypeError, match="mode=2"):
        facet.chi2("emitter", "point", colour_mode=2)


def test_a_spectral_film_renders_its_bands_from_python():
    # specfilm's channels are its bands (sorted by name), each ∫ s(λ) L(λ) dλ: under a sky of
    # radiance 2 at every wavelength, 2·50 for a triangle of height 1 and width 100 nm.
    scene = facet.load_dict({
        "type": "scene",
        "sensor": {"type": "perspective",
                   "film": {"type": "specfilm", "width": 4, "height": 4,
                            "tri": {"type": "spectrum", "value": [(500, 0), (550, 1), (600, 0)]},
                            "flat": {"type": "spectrum", "value": 1.0}},
                   "sampler": {"type": "independent", "sample_count": 32}},
        "emitter": {"type": "constant",
                    "radiance": {"type": "spectrum", "value": [(360, 2), (830, 2)]}},
    }, mode="scalar_spectral")
    image = facet.render(scene, progress=False)
    assert image.channels == ["flat", "tri"]
    mean = np.asarray(image).reshape(-1, 2).mean(axis=0)
    assert mean == pytest.approx([2 * 470, 2 * 50], rel=0.02)
    with pytest.raises(facet.Error, match="specfilm"):
        facet.load_dict({"type": "scene", "sensor": {"type": "perspective",
                                                     "film": {"type": "specfilm"}}},
                        mode="scalar_spectral")
