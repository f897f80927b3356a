"""One sampled-format microbenchmark for callgrind (issue 20: storage sized by the format): a
512 x 512 texture of FORMAT drawn over a 512 x 512 canvas with LINEAR filtering, twice, at one
thread, e.g.

    valgrind --tool=callgrind --toggle-collect='softgl::*draw*' \\
        python benchmarks/format_sampling.py RGBA16F

(instruction counts are deterministic, wall-clock under load is not). --target FORMAT draws into
a renderbuffer of that format instead of the canvas (e.g. RGBA16F with EXT_color_buffer_float),
to count what writing a format costs. --save PATH writes the
canvas as a .npy file, to compare two builds byte for byte."""
from __future__ import annotations

import argparse

import numpy as np

import softgl

VS = """#version 300 es
in vec2 pos; out vec2 uv;
void main() { uv = pos * 0.5 + 0.5; gl_Position = vec4(pos, 0.0, 1.0); }"""
FS = """#version 300 es
precision highp float; uniform sampler2D tex; in vec2 uv; out vec4 o;
void main() { o = texture(tex, uv * 1.37 + 0.11); }"""

# format -> (client format, client type, channels, values in [0, 1] as the client array)
FORMATS = {
    "RGBA8": ("RGBA", "UNSIGNED_BYTE", 4), "SRGB8_ALPHA8": ("RGBA", "UNSIGNED_BYTE", 4),
    "RGB565": ("RGB", "UNSIGNED_BYTE", 3), "RGBA4": ("RGBA", "UNSIGNED_BYTE", 4),
    "RGB5_A1": ("RGBA", "UNSIGNED_BYTE", 4),
    "RGBA32F": ("RGBA", "FLOAT", 4), "RGB32F": ("RGB", "FLOAT", 3), "RG32F": ("RG", "FLOAT", 2),
    "R32F": ("RED", "FLOAT", 1), "RGBA16F": ("RGBA", "FLOAT", 4), "RGB16F": ("RGB", "FLOAT", 3),
    "RG16F": ("RG", "FLOAT", 2), "R16F": ("RED", "FLOAT", 1),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("format", choices=sorted(FORMATS))
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--target", help="draw into a renderbuffer of this internal format")
    ap.add_argument("--save", help="write the canvas after the last draw to this .npy file")
    args = ap.parse_args()
    n = args.size
    gl = softgl.Context(n, n, threads=1, antialias=False, version=2)
    client_format, client_type, channels = FORMATS[args.format]
    rng = np.random.default_rng(7)
    if client_type == "FLOAT":
        data = rng.uniform(0, 1, (n, n, channels)).astype(np.float32)
    else:
        data = rng.integers(0, 256, (n, n, channels), dtype=np.uint8)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, args.format), n, n, 0, getattr(gl, client_format),
                  getattr(gl, client_type), data)
    for pname, value in ((gl.TEXTURE_MIN_FILTER, gl.LINEAR), (gl.TEXTURE_MAG_FILTER, gl.LINEAR)):
        gl.texParameteri(gl.TEXTURE_2D, pname, value)
    prog = softgl.program(gl, VS, FS)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32), gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "pos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    if args.target:
        gl.getExtension("EXT_color_buffer_float")
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorage(gl.RENDERBUFFER, getattr(gl, args.target), n, n)
        fb = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
        assert gl.checkFramebufferStatus(gl.FRAMEBUFFER) == gl.FRAMEBUFFER_COMPLETE
    for _ in range(2):
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        gl.finish()
    if args.save:
        out = np.empty((n, n, 4), np.float32 if args.target and "F" in args.target else np.uint8)
        gl.readPixels(0, 0, n, n, gl.RGBA, gl.FLOAT if out.dtype == np.float32 else gl.UNSIGNED_BYTE, out)
        np.save(args.save, out)


if __name__ == "__main__":
    main()
