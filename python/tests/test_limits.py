"""Limits from Python: thread counts beyond the cores."""

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
