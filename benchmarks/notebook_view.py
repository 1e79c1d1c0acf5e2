"""Benchmark: a frame of ``glsandbox.view`` (the orbitable notebook view) at 480x360.

Baseline: the headless frame ``glsandbox.show`` makes (render and read back).
Subject: one orbit step of the view, what a drag costs the kernel: the camera
turned, the frame rendered and read back (``LessonCanvas.draw``) and encoded
as the JPEG that jupyter_rfb sends while the camera moves. For phong (raster)
and for ray_interactive, whose ray-traced frame the view traces at a quarter
of the resolution each way while the camera moves. Sending it over
the wire and the browser's decoding are not in it. Needs the ``notebook``
extra (jupyter_rfb); without it the module has no case.
"""

from __future__ import annotations

SIZE = (480, 360)


def cases(env) -> list:
    try:
        from jupyter_rfb._utils import array2compressed

        from glsandbox.app.notebook_view import LessonCanvas
    except ImportError:
        env.note("notebook_view: no jupyter_rfb (the notebook extra): no view rows")
        return []
    from glsandbox.lesson import find_lesson
    from glsandbox.measure.bench import Case, Side

    def canvas_of(name: str) -> LessonCanvas:
        return LessonCanvas(find_lesson(name)(), lambda: env.renderer, SIZE)

    def show(canvas: LessonCanvas):
        return lambda k: env.renderer.render_scene(canvas.lesson.scene(), SIZE).image

    def orbit_step(canvas: LessonCanvas):
        def step(k: int):
            canvas.camera.drag(3.0, 0.0, canvas.lesson.scene())  # 3 pixels of drag: about 1 degree of orbit
            image = canvas.draw()
            array2compressed(image, canvas.quality)
            return image
        return step

    phong, ray = canvas_of("phong"), canvas_of("ray_interactive")
    return [Case("notebook view", "phong 480x360: a frame while orbiting", Side("show (render + read)", show(phong)),
                 Side("view (orbit + render + read + JPEG)", orbit_step(phong)), repeat=20),
            Case("notebook view", "ray_interactive 480x360: a frame while orbiting (traced coarse)",
                 Side("show (full resolution)", show(ray)), Side("view (orbit, quarter resolution, JPEG)",
                                                                 orbit_step(ray)), repeat=5)]
