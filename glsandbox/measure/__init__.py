"""The measuring wing: tools that judge pictures and time frames, never needed to render one.

- :mod:`~glsandbox.measure.metrics`: RMSE, PSNR, largest difference, share of differing pixels;
- :mod:`~glsandbox.measure.golden`: the golden-image rule the tests use, and its diff pictures;
- :mod:`~glsandbox.measure.compare`: ``glsandbox compare``, one lesson's variants side by side;
- :mod:`~glsandbox.measure.zfighting`: counting a planar shadow's z-fighting pixels;
- :mod:`~glsandbox.measure.bench`: ``glsandbox bench``, every ``benchmarks/*.py`` in one table of ratios;
- ``glsandbox tradeoffs``: what accuracy costs in time, knob by knob.

The rest of glsandbox never imports this package; it imports the rest.
"""
