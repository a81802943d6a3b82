"""Renders of one Scene on several Python threads at once: a render keeps its buffers to itself
(the scene, its sensor and film are only read), so the renders overlap in time and each gives
the pixels of a render made alone."""

import re
import threading
import time

import numpy as np
import pytest

import facet


def cornell_with(cornell, integrator):
    text = cornell.read_text()
    text = re.sub(r'<integrator type="path">.*?</integrator>', integrator, text, flags=re.S)
    return facet.load_string(text, search_path=[cornell.parent], res=64, spp=128)


@pytest.mark.parametrize("integrator", [
    '<integrator type="path"><integer name="max_depth" value="4"/></integrator>',
    '<integrator type="ptracer"><integer name="max_depth" value="4"/></integrator>',
])
def test_two_threads_render_one_scene_at_once(cornell, integrator):
    scene = cornell_with(cornell, integrator)
    alone = {seed: facet.render(scene, seed=seed, threads=1, progress=False).pixels
             for seed in (1, 2)}

    # Each render's progress callback (on its own Python thread) records when it saw a fraction
    # below one, i.e. while its render was running (the last fraction a render reports is 1).
    # Renders that took turns on the scene could not both report progress after the other one
    # had started reporting.
    running = {1: [], 2: []}
    images = {}
    errors = []

    def work(seed):
        def progress(fraction):
            if fraction < 1.0:
                running[seed].append(time.monotonic())

        try:
            images[seed] = facet.render(scene, seed=seed, threads=1, progress=progress).pixels
        except Exception as e:  # noqa: BLE001 (reported below, on the test's thread)
            errors.append(e)

    threads = [threading.Thread(target=work, args=(seed,)) for seed in (1, 2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert running[1] and running[2], "a render too short to report progress"
    assert running[1][-1] > running[2][0] and running[2][-1] > running[1][0], \
        f"the renders took turns: {running[1][0]:.3f}..{running[1][-1]:.3f} and " \
        f"{running[2][0]:.3f}..{running[2][-1]:.3f}"
    for seed in (1, 2):
        assert images[seed].mean() > 0.0
        np.testing.assert_array_equal(images[seed], alone[seed])
    assert not np.array_equal(images[1], images[2])  # two seeds, two images
