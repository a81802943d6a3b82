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
