"""Limits from Python: thread counts beyond the cores, and Ctrl-C during paths that would
bounce for hours."""

import os
import subprocess
import sys
import textwrap

import numpy as np

import facet

SCENE = """<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="3"/></integrator>
    <sensor type="perspective">
        <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="sphere"><bsdf type="diffuse"/></shape>
</scene>
"""

# The camera inside a closed perfect mirror: without Russian roulette (rr_depth 2^32 - 1) every
# camera path bounces some 2^32 times.
MIRROR = """<scene version="3.0.0">
    <integrator type="path">
        <integer name="max_depth" value="-1"/>
        <integer name="rr_depth" value="4294967295"/>
    </integrator>
    <sensor type="perspective">
        <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <emitter type="point"><point name="position" x="0.3" y="0.2" z="0.1"/></emitter>
    <shape type="sphere">
        <float name="radius" value="2"/>
        <bsdf type="twosided"><bsdf type="conductor"><string name="material" value="none"/></bsdf></bsdf>
    </shape>
</scene>
"""


def test_threads_beyond_the_cores_are_capped_with_one_warning(capfd):
    scene = facet.load_string(SCENE)
    reference = facet.render(scene).pixels
    capfd.readouterr()
    # Ten million threads crashed inside TBB; beyond a C int the count is capped all the same.
    for threads in (10**7, 10**12):
        image = facet.render(scene, threads=threads)
        assert np.array_equal(image.pixels, reference)
        err = capfd.readouterr().err
        warnings = [line for line in err.splitlines() if line.startswith("[W]")]
        assert len(warnings) == 1 and "hardware threads" in warnings[0], err
        assert "TBB" not in err, err


def test_ctrl_c_stops_an_endless_path(tmp_path):
    """SIGINT raises KeyboardInterrupt within moments although no sample of the render ever
    ends by itself (the stop is checked on the bounces, not only between samples)."""
    scene = tmp_path / "mirror.xml"
    scene.write_text(MIRROR)
    script = textwrap.dedent(f"""
        import os, signal, threading, time
        import facet
        scene = facet.load_file({str(scene)!r})
        threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        start = time.monotonic()
        try:
            facet.render(scene, threads=2)
            print("finished")
        except KeyboardInterrupt:
            print("interrupted after", time.monotonic() - start)
    """)
    # A hang fails here instead of holding up the whole suite.
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                       timeout=60, env=os.environ.copy())
    assert r.returncode == 0, r.stderr
    words = r.stdout.split()
    assert words[:2] == ["interrupted", "after"], r.stdout + r.stderr
    assert float(words[2]) < 10.0, r.stdout
