"""The extension objects of the blend lab: SOFTGL_exact_transparency and SOFTGL_introspection.

Both are softgl's own (docs/architecture.md, "The blend lab"): enabled with
``gl.getExtension(name)``, they never change what pure WebGL code does. Values 0x1D1xx are softgl's
(OpenGL has no such enums).

SOFTGL_exact_transparency::

    ext = gl.getExtension("SOFTGL_exact_transparency")
    gl.enable(ext.EXACT_TRANSPARENCY_SOFTGL)   # blended draws now keep their fragments
    ...draw opaque things (blending off: written as usual), then transparent ones...
    exact = ext.resolve()                      # composite in float64, write the drawing buffer
    ext.resolve(ext.DEPTH_PEELING_SOFTGL, layers=4)   # or: the k nearest layers only
    ext.resolve(ext.WEIGHTED_BLENDED_SOFTGL, weight=7)  # or: McGuire & Bavoil 2013, eq. 7-10

``resolve`` returns the unrounded float64 image (height, width, 4), rows bottom-up like
readPixels, and empties the A-buffer. ``setMemoryLimit(bytes)`` bounds the fragment records;
a draw that goes over it reports OUT_OF_MEMORY (GLWarning, or GLError in strict mode) and the
A-buffer then refuses to resolve until cleared: it never drops fragments silently.

SOFTGL_introspection::

    ext = gl.getExtension("SOFTGL_introspection")
    gl.enable(ext.INTROSPECTION_SOFTGL)
    ...draw...
    gl.fragments(x, y)    # every fragment sample that reached (x, y) since the last clear
"""
from __future__ import annotations

import weakref

EXACT_TRANSPARENCY = {
    "EXACT_TRANSPARENCY_SOFTGL": 0x1D100,
    "TRANSPARENCY_EXACT_SOFTGL": 0x1D110,
    "DEPTH_PEELING_SOFTGL": 0x1D111,
    "WEIGHTED_BLENDED_SOFTGL": 0x1D112,
}
INTROSPECTION = {"INTROSPECTION_SOFTGL": 0x1D120}

CONSTANTS = {"SOFTGL_exact_transparency": EXACT_TRANSPARENCY, "SOFTGL_introspection": INTROSPECTION}


def _check_limit(bytes_):
    if isinstance(bytes_, bool) or not isinstance(bytes_, int) or bytes_ < 0:
        raise TypeError("setMemoryLimit: bytes must be a non-negative int")
    return bytes_


def functions(name: str, gl) -> dict:
    """The functions of the extension object; they hold the context weakly (no cycles)."""
    ref = weakref.ref(gl)
    if name == "SOFTGL_exact_transparency":
        def resolve(mode=EXACT_TRANSPARENCY["TRANSPARENCY_EXACT_SOFTGL"], layers=0, weight=7):
            """Composite the captured fragments and write the drawing buffer (see module doc)."""
            return ref()._transparency_resolve(int(mode), int(layers), int(weight))

        def depthComplexity():
            """(height, width) uint32: most fragments a sample of each pixel keeps (rows bottom-up)."""
            return ref()._transparency_depth_complexity()

        return {"resolve": resolve, "depthComplexity": depthComplexity,
                "setMemoryLimit": lambda bytes_: ref()._transparency_set_limit(_check_limit(bytes_)),
                "memory": lambda: ref()._transparency_memory()}
    if name == "SOFTGL_introspection":
        return {"setMemoryLimit": lambda bytes_: ref()._introspection_set_limit(_check_limit(bytes_)),
                "memory": lambda: ref()._introspection_memory()}
    return {}
