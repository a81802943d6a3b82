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
    assert facet.modes() == ["scalar_rgb"]


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


@pytest.mark.parametrize("mode", ["scalar_spectral", "cuda_mono_polarized", "foo", "scalar_rbg"])
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
