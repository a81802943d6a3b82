"""Renders split across the workers of a Dask cluster, merged to the exact image.

    from dask.distributed import Client
    import facet.distributed

    client = Client("scheduler:8786")             # or Client(LocalCluster(n_workers=2))
    image = facet.distributed.render("scene.xml", client, tiles=(4, 2), passes=2, spp=64)
    facet.write(image, "scene.exr")

The film is cut into ``tiles`` crop windows (columns, rows) and each window into ``passes`` parts
of ``spp`` samples per pixel; every (window, pass) is one task that loads the scene on its worker
(once per worker process and scene) and renders that part. The parts come back as arrays and are
merged as ``facet merge`` merges files: windows placed where they belong, passes combined by their
raw sums (Σ w·L / Σ w over all their samples, whatever the filter). The result is bit-identical to
``facet.render(scene, passes=passes)`` of the whole film in one process (with one pass: to
``facet.render(scene)``), the same estimator as one render of passes x spp samples per pixel.
The workers must see the scene file and its assets at the same path (a shared folder, or the same machine).
"""

import os

import facet

__all__ = ["render", "tile_windows", "render_part"]

_scenes = {}


def tile_windows(width, height, tiles):
    """The crop windows (x0, y0, x1, y1) that cut a width x height film into ``tiles`` = (columns,
    rows) (an int n means n x n), row by row; sizes differ by at most one pixel."""
    if isinstance(tiles, int):
        tiles = (tiles, tiles)
    cols, rows = int(tiles[0]), int(tiles[1])
    if cols < 1 or rows < 1 or cols > width or rows > height:
        raise ValueError(f"tiles={tiles!r}: expected 1..{width} columns and 1..{height} rows")
    xs = [width * i // cols for i in range(cols + 1)]
    ys = [height * j // rows for j in range(rows + 1)]
    return [(xs[i], ys[j], xs[i + 1], ys[j + 1]) for j in range(rows) for i in range(cols)]


def _scene(path, params):
    key = (path, tuple(sorted(params.items())))
    scene = _scenes.get(key)
    if scene is None:
        scene = facet.load_file(path, **params)
        _scenes[key] = scene
    return scene


def _worker_threads():
    """The threads of the Dask worker this task runs on (its ``nthreads``, the
    ``threads_per_worker`` of a LocalCluster), or None outside a worker (every core)."""
    try:
        from distributed import get_worker

        worker = get_worker()
        state = getattr(worker, "state", None)  # distributed >= 2022.11 keeps it there
        n = int(state.nthreads if state is not None else worker.nthreads)
    except Exception:
        return None
    return n if n > 0 else None


def render_part(scene_path, params, crop, pass_index, passes, spp=None, seed=0, sensor=0,
                threads=None):
    """One task: renders window ``crop`` of pass ``pass_index`` of ``passes`` and returns it as a
    plain dict (what ``facet.merge`` takes back with ``facet.Image.from_part``)."""
    scene = _scene(scene_path, params)
    if threads is None:
        threads = _worker_threads()
    image = facet.render(scene, spp=spp, seed=seed, sensor=sensor, threads=threads, crop=crop,
                         pass_index=pass_index, passes=passes, progress=False)
    return image.to_part()


def render(scene_path, client, tiles=(2, 2), passes=1, spp=None, seed=0, sensor=0, threads=None,
           params=None, output=None):
    """Renders ``scene_path`` on the workers of the Dask ``client`` and returns the merged
    ``facet.Image``; writes it to ``output`` too when given. ``params`` are the scene's ``$name``
    values (``-D``), ``threads`` the threads of each task (default: its worker's ``nthreads``,
    the ``threads_per_worker`` of a LocalCluster)."""
    scene_path = os.path.abspath(os.fspath(scene_path))
    params = {k: facet._param_value(k, v) for k, v in (params or {}).items()}
    if int(passes) < 1:
        raise ValueError(f"passes={passes!r}: expected at least 1")
    # The film size, from parsing the scene (no plugin, mesh or BVH on the client).
    sensors = facet.scene_info(scene_path, **params)["sensors"]
    if not 0 <= int(sensor) < len(sensors):
        raise facet.Error(f"sensor {sensor}: the scene has {len(sensors)} sensors")
    width, height = sensors[int(sensor)]["film_size"]
    windows = tile_windows(width, height, tiles)
    futures = [
        client.submit(render_part, scene_path, params, crop, p, int(passes), spp, seed, sensor,
                      threads, pure=False)
        for p in range(int(passes))
        for crop in windows
    ]
    parts = client.gather(futures)
    merged = facet.merge([facet.Image.from_part(p) for p in parts])
    if output is not None:
        facet.write(merged, output)
    return merged
