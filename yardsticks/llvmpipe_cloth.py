"""Mesa llvmpipe on the cloth-N render workload, to run beside `hooke bench render` and
see both under the same machine conditions.

N x N grid (two triangles per square, indexed), per-vertex normals, Lambert shading, depth
test, 1024x1024 output with 4x supersampling (drawn at 2048x2048, then averaged down by a
linear blit). Prints the median of REPEAT frames, without and with the vertex upload and
pixel read-back a simulation needs each frame.

    pip install moderngl numpy          # Mesa's EGL and DRI drivers from the system
    LP_NUM_THREADS=2 python3 yardsticks/llvmpipe_cloth.py 256 9
    LP_NUM_THREADS=2 python3 yardsticks/llvmpipe_cloth.py 1024 5
"""
import os, sys, time, statistics, json
import numpy as np
import moderngl

N = int(sys.argv[1]) if len(sys.argv) > 1 else 256
REPEAT = int(sys.argv[2]) if len(sys.argv) > 2 else 9
W = H = 1024
SS = 2

ctx = moderngl.create_standalone_context(backend="egl")
prog = ctx.program(
    vertex_shader="""
        #version 330
        uniform mat4 mvp;
        in vec3 pos; in vec3 nrm;
        out vec3 n;
        void main() { n = nrm; gl_Position = mvp * vec4(pos, 1.0); }
    """,
    fragment_shader="""
        #version 330
        in vec3 n; out vec4 colour;
        void main() {
            vec3 l = normalize(vec3(0.3, 1.0, 0.5));
            float d = abs(dot(normalize(n), l));
            colour = vec4(vec3(0.2, 0.45, 0.8) * (0.25 + 0.75 * d), 1.0);
        }
    """,
)
# The workload grid in the x-z plane at y = 1, with a gentle fold so normals vary.
i, j = np.meshgrid(np.arange(N), np.arange(N), indexing="ij")
h = 1.0 / (N - 1)
x, z = i * h, j * h
y = 1.0 + 0.05 * np.sin(6 * x) * np.cos(5 * z)
pos = np.stack([x, y, z], -1).reshape(-1, 3).astype("f4")
nrm = np.stack([-0.3 * np.cos(6 * x), np.ones_like(x), 0.25 * np.sin(5 * z)], -1)
nrm = (nrm / np.linalg.norm(nrm, axis=-1, keepdims=True)).reshape(-1, 3).astype("f4")
q = (i[:-1, :-1] * N + j[:-1, :-1]).ravel()
idx = np.stack([q, q + N, q + 1, q + 1, q + N, q + N + 1], -1).astype("i4").ravel()
vertices = np.hstack([pos, nrm]).astype("f4")
vbo = ctx.buffer(vertices.tobytes())
ibo = ctx.buffer(idx.tobytes())
vao = ctx.vertex_array(prog, [(vbo, "3f 3f", "pos", "nrm")], ibo)


def look_at(eye, target, up):
    f = target - eye; f /= np.linalg.norm(f)
    s = np.cross(f, up); s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.identity(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective(fovy, aspect, near, far):
    t = 1 / np.tan(np.radians(fovy) / 2)
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1] = t / aspect, t
    m[2, 2], m[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    m[3, 2] = -1
    return m


mvp = perspective(40, 1, 0.05, 10) @ look_at(np.array([0.5, 2.0, 2.0]), np.array([0.5, 1.0, 0.5]), np.array([0.0, 1.0, 0.0]))
prog["mvp"].write(mvp.T.astype("f4").tobytes())

big = ctx.framebuffer(ctx.renderbuffer((W * SS, H * SS)), ctx.depth_renderbuffer((W * SS, H * SS)))
out = ctx.framebuffer(ctx.renderbuffer((W, H)))
ctx.enable(moderngl.DEPTH_TEST)


def frame(upload):
    if upload:
        vbo.write(vertices.tobytes())
    big.use()
    big.clear(0.9, 0.92, 0.95, 1.0, depth=1.0)
    vao.render(moderngl.TRIANGLES)
    ctx.copy_framebuffer(out, big)  # linear downsample of the 2x2 samples
    if upload:
        return out.read(components=4)
    ctx.finish()


for upload in (False, True):
    frame(upload)
    times = []
    for _ in range(REPEAT):
        t = time.perf_counter()
        frame(upload)
        times.append((time.perf_counter() - t) * 1e3)
    print(json.dumps({"scene": f"cloth-{N}", "triangles": len(idx) // 3, "upload_and_readback": upload,
                      "threads": os.environ.get("LP_NUM_THREADS", "default"),
                      "median_ms": round(statistics.median(times), 1)}))
