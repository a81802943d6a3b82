"""facet.distributed on a LocalCluster of two worker processes: bit-identical to one process."""

import numpy as np
import pytest

import facet
import facet.distributed

distributed = pytest.importorskip("distributed")

PARAMS = dict(res=48, spp=4, max_depth=3)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=40)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_tile_windows():
    w = facet.distributed.tile_windows(10, 7, (3, 2))
    assert w[0] == (0, 0, 3, 3) and w[-1] == (6, 3, 10, 7) and len(w) == 6
    covered = np.zeros((7, 10), int)
    for x0, y0, x1, y1 in w:
        covered[y0:y1, x0:x1] += 1
    assert (covered == 1).all()
    with pytest.raises(ValueError):
        facet.distributed.tile_windows(4, 4, (5, 1))


def test_tiles_are_bit_identical_to_one_process(client, cornell, tmp_path):
    out = tmp_path / "dask.exr"
    image = facet.distributed.render(cornell, client, tiles=(3, 2), params=PARAMS, seed=3,
                                     output=out)
    single = facet.render(facet.load_file(cornell, **PARAMS), seed=3)
    assert image.channels == single.channels
    assert np.array_equal(image.pixels, single.pixels)
    # Both worker processes took part: each loaded the scene (cached per process).
    loaded = client.run(lambda: len(facet.distributed._scenes))
    assert len(loaded) == 2 and all(n >= 1 for n in loaded.values()), loaded
    # The file is the one the single render writes, pixel for pixel.
    mine = tmp_path / "single.exr"
    facet.write(single, mine)
    assert np.array_equal(facet.read(out)[0], facet.read(mine)[0])


def test_a_mono_render_is_bit_identical_to_one_process(client, cornell):
    image = facet.distributed.render(cornell, client, tiles=(2, 1), params=PARAMS, seed=2,
                                     mode="llvm_mono")
    single = facet.render(facet.load_file(cornell, mode="scalar_mono", **PARAMS), seed=2)
    assert image.metadata["facet:mode"] == "scalar_mono"
    assert np.array_equal(image.pixels, single.pixels)
    assert np.array_equal(image.pixels[..., 0], image.pixels[..., 1])
    with pytest.raises(facet.Error, match="scalar_rgb, scalar_mono, scalar_spectral"):
        facet.distributed.render(cornell, client, params=PARAMS, mode="scalar_rgb_polarized")


def test_passes_are_bit_identical_to_one_process(client, cornell):
    image = facet.distributed.render(cornell, client, tiles=(2, 2), passes=2, params=PARAMS)
    scene = facet.load_file(cornell, **PARAMS)
    # The two passes rendered in one process, without tiles (the gaussian filter reaches across
    # the tiles' edges: the parts merge by their raw sums).
    single = facet.render(scene, passes=2)
    assert image.channels == single.channels == ["R", "G", "B"]
    assert np.array_equal(image.pixels, single.pixels)
    assert image.metadata["facet:spp"] == "8"
    # ... which is also the merge of the two whole-film passes.
    local = facet.merge([facet.render(scene, pass_index=i, passes=2) for i in range(2)])
    assert np.array_equal(image.pixels, local.pixels)


EDITABLE = """<scene version="3.0.0">
    <default name="albedo" value="0.5"/>
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
    </sensor>
    <include filename="light.xml"/>
    <shape type="obj">
        <string name="filename" value="quad.obj"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="$albedo"/></bsdf>
    </shape>
</scene>
"""

LIGHT = """<scene version="3.0.0">
    <emitter type="constant"><rgb name="radiance" value="{}"/></emitter>
</scene>
"""

QUAD = """v -{s} -{s} 0
v {s} -{s} 0
v {s} {s} 0
v -{s} {s} 0
f 1 2 3
f 1 3 4
"""


def test_an_edited_scene_is_rendered_anew(client, tmp_path):
    """A worker used to keep a scene by its path: after an edit the same client got the old
    image back. Edits of the scene file, of a file it includes and of a mesh it names each give
    the image of the edited scene."""
    scene = tmp_path / "scene.xml"
    scene.write_text(EDITABLE)
    (tmp_path / "light.xml").write_text(LIGHT.format(1))
    (tmp_path / "quad.obj").write_text(QUAD.format(s=1))

    def both():
        dask = facet.distributed.render(scene, client, tiles=(2, 1))
        local = facet.render(facet.load_file(scene))
        assert np.array_equal(dask.pixels, local.pixels)
        return dask.pixels

    images = [both()]
    scene.write_text(EDITABLE.replace('value="0.5"', 'value="0.9"'))
    images.append(both())
    (tmp_path / "light.xml").write_text(LIGHT.format(2))
    images.append(both())
    (tmp_path / "quad.obj").write_text(QUAD.format(s=0.5))
    images.append(both())
    for i in range(1, len(images)):
        assert not np.array_equal(images[i - 1], images[i]), f"edit {i} changed nothing"


def test_the_worker_cache_is_bounded(client, tmp_path):
    scene = tmp_path / "scene.xml"
    scene.write_text(EDITABLE)
    (tmp_path / "light.xml").write_text(LIGHT.format(1))
    (tmp_path / "quad.obj").write_text(QUAD.format(s=1))
    # Every albedo is another scene for the cache; each worker keeps a few.
    for albedo in range(8):
        facet.distributed.render(scene, client, tiles=(2, 1), params=dict(albedo=albedo / 8))
    cached = client.run(lambda: len(facet.distributed._scenes))
    assert all(1 <= n <= facet.distributed._CACHE_SIZE for n in cached.values()), cached


def test_scene_hash_follows_the_files(tmp_path):
    scene = tmp_path / "scene.xml"
    scene.write_text(EDITABLE)
    (tmp_path / "light.xml").write_text(LIGHT.format(1))
    (tmp_path / "quad.obj").write_text(QUAD.format(s=1))
    files = facet.distributed._scene_files(str(scene), {})
    assert files == sorted(str(tmp_path / n) for n in ("scene.xml", "light.xml", "quad.obj"))
    h = facet.distributed.scene_hash(scene)
    assert h == facet.distributed.scene_hash(scene)
    assert h != facet.distributed.scene_hash(scene, dict(albedo=0.25))
    (tmp_path / "quad.obj").write_text(QUAD.format(s=2))
    assert h != facet.distributed.scene_hash(scene)
