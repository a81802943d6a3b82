"""facet.render with crop windows and passes, and facet.merge of what it returns (and of the
CLI's files)."""

import subprocess

import numpy as np
import pytest

import facet

SMALL = dict(res=40, spp=4, max_depth=3)


@pytest.fixture
def scene(cornell):
    return facet.load_file(cornell, **SMALL)


def test_crop_is_the_same_pixels(scene):
    full = facet.render(scene, seed=2)
    crop = facet.render(scene, seed=2, crop=(5, 7, 30, 21))
    assert crop.pixels.shape == (14, 25, 3)
    assert crop.window == (5, 7, 40, 40)
    assert np.array_equal(crop.pixels, full.pixels[7:21, 5:30])
    assert crop.metadata["facet:crop"] == "5 7 30 21"


def test_merge_crops_is_bit_identical(scene, cornell, facet_cli, cli_env, tmp_path):
    full = facet.render(scene, seed=1)
    parts = [facet.render(scene, seed=1, crop=c) for c in
             [(0, 0, 40, 13), (0, 13, 11, 40), (11, 13, 40, 40)]]
    merged = facet.merge(parts[::-1])
    assert merged.channels == full.channels
    assert np.array_equal(merged.pixels, full.pixels)
    assert merged.half == full.half and merged.window == (0, 0, 40, 40)

    # Parts from the Python API and from the CLI mix: the same scene identity, the same pixels.
    cli_part = tmp_path / "top.exr"
    cmd = [str(facet_cli), "render", str(cornell), "-q", "--seed", "1", "--crop", "0", "0", "40",
           "13", "-o", str(cli_part)] + [f"-D{k}={v}" for k, v in SMALL.items()]
    subprocess.run(cmd, check=True, env=cli_env)
    assert facet.read(cli_part)[0].shape == (13, 40, 3)
    mixed = facet.merge([str(cli_part), parts[1], parts[2]])
    half = full.pixels.astype(np.float16).astype(np.float32)
    assert np.array_equal(mixed.pixels[:13], half[:13])
    assert np.array_equal(mixed.pixels[13:], full.pixels[13:])


def test_merged_passes_are_the_render_of_all_passes(scene):
    p = [facet.render(scene, seed=4, spp=4, pass_index=i, passes=3) for i in range(3)]
    assert [x.metadata["facet:pass_index"] for x in p] == ["0", "1", "2"]
    # Every part carries its raw sums after R, G, B.
    assert p[0].channels == ["R", "G", "B", "facet.sum.R", "facet.sum.G", "facet.sum.B",
                             "facet.weight"]
    merged = facet.merge(p)
    assert merged.channels == ["R", "G", "B"]
    assert merged.metadata["facet:spp"] == "12"
    # Bit-identical to the three passes rendered in one process (Σ w·L / Σ w over all their
    # samples, with the scene's gaussian filter).
    single = facet.render(scene, seed=4, spp=4, passes=3)
    assert single.channels == ["R", "G", "B"]
    assert np.array_equal(merged.pixels, single.pixels)
    # Crops of the passes merge to the same pixels.
    tiles = [facet.render(scene, seed=4, spp=4, pass_index=i, passes=3, crop=c)
             for i in range(3) for c in ([(0, 0, 40, 40)] if i == 1 else
                                         [(0, 0, 40, 17), (0, 17, 23, 40), (23, 17, 40, 40)])]
    assert np.array_equal(facet.merge(tiles[::-1]).pixels, single.pixels)
    # The spp-weighted mean of the developed passes (what merges took before) is another
    # estimator: pixels differ by far more than rounding, the image's brightness only a little.
    mean = sum(x.pixels[..., :3].astype(np.float64) for x in p) / 3.0
    assert not np.allclose(merged.pixels, mean, rtol=1e-3)
    assert abs(merged.pixels.mean() / mean.mean() - 1.0) < 0.02
    # The passes are independent: no two are the same image.
    assert not np.array_equal(p[0].pixels, p[1].pixels)
    # And their merge estimates the 12-spp render: close on the mean brightness.
    whole = facet.render(scene, seed=4, spp=12)
    assert abs(merged.pixels.mean() / whole.pixels.mean() - 1.0) < 0.05


def test_merge_refuses_bad_sets(scene, cornell):
    top = facet.render(scene, crop=(0, 0, 40, 20))
    bottom = facet.render(scene, crop=(0, 20, 40, 40))
    wide = facet.render(scene, crop=(0, 15, 40, 40))
    with pytest.raises(facet.Error, match=r"overlap.*\[15, 20\)"):
        facet.merge([top, wide])
    with pytest.raises(facet.Error, match=r"800 of the 40x40 pixels uncovered.*\[0, 40\) x \[20, 40\)"):
        facet.merge([top])
    other = facet.render(facet.load_file(cornell, res=40, spp=4, max_depth=5), crop=(0, 20, 40, 40))
    with pytest.raises(facet.Error, match="different scenes"):
        facet.merge([top, other])
    with pytest.raises(facet.Error, match="different seeds"):
        facet.merge([top, facet.render(scene, seed=9, crop=(0, 20, 40, 40))])
    mono = facet.load_file(cornell, mode="scalar_mono", **SMALL)
    with pytest.raises(facet.Error, match="rendered in the mode scalar_mono, .* in scalar_rgb: "
                                          "parts of different colour modes"):
        facet.merge([top, facet.render(mono, crop=(0, 20, 40, 40))])
    assert facet.merge([facet.render(mono, crop=(0, 0, 40, 20)),
                        facet.render(mono, crop=(0, 20, 40, 40))]).metadata["facet:mode"] == \
        "scalar_mono"
    with pytest.raises(facet.Error, match="pass 1 of 2 is missing"):
        facet.merge([facet.render(scene, pass_index=0, passes=2)])
    with pytest.raises(facet.Error, match="no parts"):
        facet.merge([])
    assert np.array_equal(facet.merge([top, bottom]).pixels, facet.render(scene).pixels)
