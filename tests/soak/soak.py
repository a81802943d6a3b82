#!/usr/bin/env python3
"""Soak runs (ctest label `soak`, registered with -DFACET_SOAK=ON): long renders and long
chi-square runs that exercise the rare sample values a short test never draws (a sampler's exact 0,
a cell at a pole, the last entry of a table), to show that nothing crashes, hangs or turns NaN.

  soak.py render FACET WORKDIR SAMPLER [EMITTER_SAMPLES]
      Renders a generated scene lit by a sky with a bright zenith (envmap), a rectangle, a sphere
      and a cylinder area light, a spot and a point light, with the `direct` integrator and
      SAMPLER; the image must be finite. Prints how many emitter samples the render drew.
  soak.py ptracer FACET WORKDIR
      The same scene with the particle tracer: the emitters' sample_ray().
  soak.py chi2 FACET CONFIGS LINE SAMPLES TESTS
      `facet chi2` on the emitter configuration at line LINE of CONFIGS with SAMPLES samples, at
      the family-wise level of TESTS such runs.

Every run must end with exit status 0 within its ctest timeout; a signal, a non-finite pixel or a
failed test fails it.
"""
import math, os, re, shlex, struct, subprocess, sys, time

RES, SPP = 128, 64


def write_pfm(path, width, height, pixel):
    """A colour PFM (little-endian); PFM rows run from the bottom of the image up."""
    rows = []
    for y in reversed(range(height)):
        rows.append(b''.join(struct.pack('<3f', *pixel(x, y)) for x in range(width)))
    with open(path, 'wb') as f:
        f.write(b'PF\n%d %d\n-1.0\n' % (width, height))
        f.write(b''.join(rows))


def read_pfm(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = f.read()
    channels = 3 if kind == b'PF' else 1
    count = width * height * channels
    return struct.unpack(('<' if scale < 0 else '>') + '%df' % count, data[:4 * count])


def sky(x, y, width=64, height=32):
    """Bright near the zenith (the first rows: the +Y pole), a dim blue sky, a dark ground."""
    v = y / (height - 1)
    if v < 0.08:
        return (900.0, 850.0, 700.0)
    if v < 0.5:
        return (0.3, 0.45, 0.8 + 0.2 * math.cos(2 * math.pi * x / width))
    return (0.05, 0.04, 0.03)


SCENE = """<scene version="3.0.0">
    <integrator type="{integrator}">{integrator_params}</integrator>
    <sensor type="perspective">
        <float name="fov" value="50"/>
        <transform name="to_world"><lookat origin="0, 2, 6" target="0, 0.5, 0" up="0, 1, 0"/></transform>
        <sampler type="{sampler}"><integer name="sample_count" value="{spp}"/></sampler>
        <film type="hdrfilm"><integer name="width" value="{res}"/><integer name="height" value="{res}"/>
            <rfilter type="gaussian"/></film>
    </sensor>
    <emitter type="envmap"><string name="filename" value="sky.pfm"/>
        <transform name="to_world"><rotate x="1" angle="3"/></transform></emitter>
    <emitter type="spot"><rgb name="intensity" value="30"/>
        <transform name="to_world"><lookat origin="2, 4, 2" target="0, 0, 0"/></transform></emitter>
    <emitter type="point"><point name="position" value="-2, 3, 1"/><rgb name="intensity" value="10"/></emitter>
    <shape type="rectangle">
        <transform name="to_world"><scale value="6"/><rotate x="1" angle="-90"/></transform>
        <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/><translate y="3"/></transform>
        <emitter type="area"><rgb name="radiance" value="8"/></emitter>
    </shape>
    <shape type="sphere"><point name="center" value="1, 0.6, 0"/><float name="radius" value="0.6"/>
        <bsdf type="roughplastic"/></shape>
    <shape type="sphere"><point name="center" value="-1.2, 0.4, 0.5"/><float name="radius" value="0.3"/>
        <emitter type="area"><rgb name="radiance" value="4"/></emitter></shape>
    <shape type="cylinder"><point name="p0" value="0, 0, -1.5"/><point name="p1" value="0, 1.5, -1.5"/>
        <float name="radius" value="0.2"/><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>
</scene>
"""


def render(facet, work, sampler, integrator, params, emitter_samples):
    os.makedirs(work, exist_ok=True)
    write_pfm(os.path.join(work, 'sky.pfm'), 64, 32, sky)
    name = f'{integrator}-{sampler}'
    xml = os.path.join(work, name + '.xml')
    with open(xml, 'w') as f:
        f.write(SCENE.format(integrator=integrator, integrator_params=params, sampler=sampler,
                             spp=SPP, res=RES))
    out = os.path.join(work, name + '.pfm')
    start = time.monotonic()
    p = subprocess.run([facet, 'render', xml, '-o', out], cwd=work, stdout=subprocess.PIPE,
                       text=True)
    seconds = time.monotonic() - start
    if p.returncode != 0:
        sys.exit(f'{name}: facet render ended with status {p.returncode}')
    # The sampler may round the count (stratified, orthogonal): take the one the render used.
    spp = int(re.search(r', (\d+) spp', p.stdout).group(1))
    pixels = read_pfm(out)
    bad = sum(1 for v in pixels if not math.isfinite(v))
    if bad:
        sys.exit(f'{name}: {bad} non-finite pixel values')
    if emitter_samples:
        print(f'{name}: {RES * RES * spp * emitter_samples:,} emitter samples in {seconds:.1f} s, '
              'every pixel finite')
    else:
        print(f'{name}: {RES * RES * spp:,} light paths in {seconds:.1f} s, every pixel finite')


def chi2(facet, configs, line, samples, tests):
    text = open(configs).read().splitlines()[int(line) - 1]
    args = shlex.split(text.replace('@CHI2_DATA@', os.path.dirname(os.path.abspath(configs))))
    if '--samples' in args:  # the line's own (small) count gives way to the soak's
        at = args.index('--samples')
        del args[at:at + 2]
    start = time.monotonic()
    p = subprocess.run([facet, 'chi2', *args, '--samples', str(samples), '--tests', str(tests)],
                       stdout=subprocess.PIPE,
                       text=True)
    print(p.stdout, end='')
    print(f'chi2 line {line}: {samples:,} samples in {time.monotonic() - start:.1f} s, '
          f'status {p.returncode}')
    if p.returncode == 0:
        return
    # What the soak is for: no signal, no sample that is not finite or lands where the pdf is
    # zero, weights and pdfs that agree. At 1e8 samples Pearson's statistic alone can reject an
    # emitter whose directions end at a silhouette (a cylinder seen from the side): the expected
    # counts of the cells the silhouette cuts come from integrating a pdf with a jump, to about a
    # per cent, while a cell holds 1e5 samples. Such a rejection is reported, not failed; any
    # other failure fails.
    failures = [l.strip() for l in p.stdout.splitlines() if l.strip().startswith('failure:')]
    if p.returncode == 1 and failures and all('histogram does not match' in f for f in failures):
        print(f'chi2 line {line}: NOTE Pearson test rejected at {samples:,} samples; every other '
              'check passed')
        return
    sys.exit(f'chi2 line {line}: status {p.returncode}')


def main():
    what = sys.argv[1]
    if len(sys.argv) > 2:
        sys.argv[2] = os.path.abspath(sys.argv[2])  # the facet command; runs elsewhere
    if what == 'render':
        facet, work, sampler = sys.argv[2:5]
        emitter_samples = int(sys.argv[5]) if len(sys.argv) > 5 else 64
        render(facet, work, sampler, 'direct',
               f'<integer name="emitter_samples" value="{emitter_samples}"/>'
               '<integer name="bsdf_samples" value="1"/>', emitter_samples)
    elif what == 'ptracer':
        facet, work = sys.argv[2:4]
        render(facet, work, 'independent', 'ptracer', '<integer name="max_depth" value="4"/>', 0)
    elif what == 'chi2':
        chi2(*sys.argv[2:5], int(sys.argv[5]), int(sys.argv[6]))
    else:
        sys.exit(__doc__)


if __name__ == '__main__':
    main()
