"""The measuring wing: tools that judge pictures and time frames; nothing here is needed to render one.
Grading submissions is :mod:`glsandbox.grading`, which uses this wing.

- :mod:`~glsandbox.measure.metrics`: RMSE, PSNR, largest difference, share of differing pixels;
- :mod:`~glsandbox.measure.golden`: the golden-image rule of the tests, and its diff pictures;
- :mod:`~glsandbox.measure.compare`: ``glsandbox compare``, one lesson's variants side by side;
- :mod:`~glsandbox.measure.zfighting`: counting the z-fighting pixels of a planar shadow;
- :mod:`~glsandbox.measure.bench`: ``glsandbox bench``, every ``benchmarks/*.py`` in one table of ratios;
  :mod:`~glsandbox.measure.bench_tables`: its ``--json`` figures as the docs site's tables;
- :mod:`~glsandbox.measure.margin`: a reference's margin, how near a decision each pixel is;
- :mod:`~glsandbox.measure.shadow_state`: lit or shadowed per pixel, a shadow technique scored
  against the ray tracer's shadow rays; :mod:`~glsandbox.measure.far_raster`: oracles for the
  rasterizer far from the origin and at small scale;
- ``glsandbox tradeoffs``, what accuracy costs in time: :mod:`~glsandbox.measure.knob` (the knob
  type and registry), :mod:`~glsandbox.measure.knobs` (the built-in knobs, one module each),
  :mod:`~glsandbox.measure.render_context` (rendering a setting, supersampling),
  :mod:`~glsandbox.measure.tradeoffs` (timing and comparing, :func:`~glsandbox.measure.tradeoffs.run`),
  :mod:`~glsandbox.measure.timing_pass` (a timing pass in a process of its own),
  :mod:`~glsandbox.measure.tradeoffs_report` (CSV, Markdown, plot) and
  :mod:`~glsandbox.measure.extra` (its optional dependencies, the ``measure`` extra).

The wing uses the rest of glsandbox; the rest uses it only from the commands
of :mod:`glsandbox.cli`, imported when the command runs.
"""
