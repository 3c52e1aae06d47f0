"""Off-screen rendering of a :class:`viewer.core.scene.Scene` with OSMesa and fixed-function OpenGL.

A :class:`Renderer` owns one OSMesa context and must be used from the thread that created it.
Primitive shapes are tessellated and uploaded once (unit sphere, cylinder and box, scaled per
object); each mesh is uploaded once as vertex and index buffers when first drawn, and freed once its
geometry has left the scene. A large mesh is drawn at the level of detail its size on screen
needs (viewer.core.geometry.MeshLevels): the coarsest whose grid is at most ``LOD_PIXELS`` of a
pixel where the mesh comes nearest the camera; each level drawn is uploaded once. Lighting: two
white directional lights fixed to the camera and an ambient term, so faces turned to the viewer are
bright and the hue of every object is kept. Closed outward shapes are drawn with back faces culled;
open or inverted meshes (many Kautham meshes) with both sides lit. A grid on the
world's z = 0 plane shows the floor.
"""
from __future__ import annotations

import ctypes
import math
import os

os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

import numpy as np  # noqa: E402
from OpenGL import GL, arrays, osmesa  # noqa: E402
from OpenGL.raw.GL.VERSION import GL_1_1 as _raw  # noqa: E402  (no per-call bookkeeping)

from viewer.errors import ViewerError  # noqa: E402
from viewer.core.geometry import unit_box, unit_cylinder, unit_sphere  # noqa: E402
from viewer.core.scene import Scene  # noqa: E402

_STRIDE = 6 * 4  # interleaved x, y, z, nx, ny, nz as float32

#: A mesh is drawn at the coarsest level of detail whose clustering grid is at most this share
#: of a pixel where the mesh comes nearest the camera: its vertices move by less than a cell's
#: diagonal (1.7 pixels; on the grasp scene 143 of 307,200 pixels change by more than 40 of 255).
LOD_PIXELS = 1.0


class _Buffer:
    """A vertex buffer (and, for primitives, an index buffer) on the GPU."""

    def __init__(self, vertices: np.ndarray, normals: np.ndarray, indices=None) -> None:
        data = np.ascontiguousarray(np.hstack([vertices, normals]), dtype=np.float32)
        self.vbo = int(GL.glGenBuffers(1))
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo)
        GL.glBufferData(GL.GL_ARRAY_BUFFER, data.nbytes, data, GL.GL_STATIC_DRAW)
        self.ibo = None
        if indices is not None:
            idx = np.ascontiguousarray(indices, dtype=np.uint32)
            self.ibo = int(GL.glGenBuffers(1))
            GL.glBindBuffer(GL.GL_ELEMENT_ARRAY_BUFFER, self.ibo)
            GL.glBufferData(GL.GL_ELEMENT_ARRAY_BUFFER, idx.nbytes, idx, GL.GL_STATIC_DRAW)
            GL.glBindBuffer(GL.GL_ELEMENT_ARRAY_BUFFER, 0)
            self.count = len(idx)
        else:
            self.count = len(data)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)

    def draw(self) -> None:
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, self.vbo)
        _raw.glVertexPointer(3, GL.GL_FLOAT, _STRIDE, ctypes.c_void_p(0))
        _raw.glNormalPointer(GL.GL_FLOAT, _STRIDE, ctypes.c_void_p(12))
        if self.ibo is not None:
            GL.glBindBuffer(GL.GL_ELEMENT_ARRAY_BUFFER, self.ibo)
            _raw.glDrawElements(GL.GL_TRIANGLES, self.count, GL.GL_UNSIGNED_INT,
                                ctypes.c_void_p(0))
            GL.glBindBuffer(GL.GL_ELEMENT_ARRAY_BUFFER, 0)
        else:
            GL.glDrawArrays(GL.GL_TRIANGLES, 0, self.count)

    def delete(self) -> None:
        GL.glDeleteBuffers(1, [self.vbo])
        if self.ibo is not None:
            GL.glDeleteBuffers(1, [self.ibo])


class Renderer:
    """An OSMesa context of ``width`` x ``height`` pixels that renders scenes to RGB arrays."""

    def __init__(self, width: int = 640, height: int = 480) -> None:
        self._context = osmesa.OSMesaCreateContextExt(osmesa.OSMESA_RGBA, 24, 0, 0, None)
        if not self._context:
            raise ViewerError("OSMesa could not create a context (is libosmesa6 installed and "
                              "PYOPENGL_PLATFORM=osmesa set?)")
        self.width = self.height = 0
        self._pixels = None
        self.resize(width, height)
        self._primitives = {"sphere": _Buffer(*unit_sphere()),
                            "cylinder": _Buffer(*unit_cylinder()),
                            "box": _Buffer(*unit_box())}
        self._meshes: dict = {}
        self.uploads = 0  # meshes uploaded so far (tests check that a mesh goes up once)
        self._setup_state()

    # -- context ---------------------------------------------------------------------------
    def resize(self, width: int, height: int) -> None:
        """Makes the framebuffer ``width`` x ``height`` pixels (buffers and meshes stay)."""
        if (width, height) == (self.width, self.height):
            return
        pixels = arrays.GLubyteArray.zeros((height, width, 4))
        if not osmesa.OSMesaMakeCurrent(self._context, pixels, GL.GL_UNSIGNED_BYTE, width, height):
            raise ViewerError(f"OSMesa could not make a {width}x{height} framebuffer current")
        self._pixels = pixels
        self.width, self.height = width, height
        GL.glViewport(0, 0, width, height)

    def close(self) -> None:
        """Frees the GPU buffers and the context (idempotent)."""
        if self._context is None:
            return
        for buffer in [*self._primitives.values(), *self._meshes.values()]:
            buffer.delete()
        self._primitives, self._meshes = {}, {}
        osmesa.OSMesaDestroyContext(self._context)
        self._context = None

    def __enter__(self) -> "Renderer":
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def _setup_state(self) -> None:
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glDepthFunc(GL.GL_LEQUAL)
        GL.glEnable(GL.GL_NORMALIZE)  # primitives are scaled per object
        GL.glShadeModel(GL.GL_SMOOTH)
        GL.glLightModelfv(GL.GL_LIGHT_MODEL_AMBIENT, (0.22, 0.22, 0.22, 1.0))
        GL.glCullFace(GL.GL_BACK)
        GL.glEnable(GL.GL_LIGHT0)
        GL.glLightfv(GL.GL_LIGHT0, GL.GL_DIFFUSE, (0.72, 0.72, 0.72, 1.0))
        GL.glLightfv(GL.GL_LIGHT0, GL.GL_SPECULAR, (0.0, 0.0, 0.0, 1.0))
        GL.glLightfv(GL.GL_LIGHT0, GL.GL_AMBIENT, (0.0, 0.0, 0.0, 1.0))
        GL.glEnable(GL.GL_LIGHT1)
        GL.glLightfv(GL.GL_LIGHT1, GL.GL_DIFFUSE, (0.3, 0.3, 0.3, 1.0))
        GL.glLightfv(GL.GL_LIGHT1, GL.GL_SPECULAR, (0.0, 0.0, 0.0, 1.0))
        GL.glLightfv(GL.GL_LIGHT1, GL.GL_AMBIENT, (0.0, 0.0, 0.0, 1.0))
        GL.glEnable(GL.GL_COLOR_MATERIAL)
        GL.glColorMaterial(GL.GL_FRONT_AND_BACK, GL.GL_AMBIENT_AND_DIFFUSE)
        GL.glMaterialfv(GL.GL_FRONT_AND_BACK, GL.GL_SPECULAR, (0.0, 0.0, 0.0, 1.0))
        GL.glBlendFunc(GL.GL_SRC_ALPHA, GL.GL_ONE_MINUS_SRC_ALPHA)
        GL.glPixelStorei(GL.GL_PACK_ALIGNMENT, 1)
        GL.glEnable(GL.GL_LINE_SMOOTH)
        GL.glHint(GL.GL_LINE_SMOOTH_HINT, GL.GL_NICEST)

    # -- drawing ---------------------------------------------------------------------------
    def render(self, scene: Scene) -> np.ndarray:
        """Draws ``scene`` from its camera; returns the frame (height, width, 3) uint8 RGB,
        row 0 at the top. The framebuffer follows the camera's image size."""
        camera = scene.camera
        if (camera.width, camera.height) == (self.width, self.height):
            # another Renderer may have been made current on this thread since
            osmesa.OSMesaMakeCurrent(self._context, self._pixels, GL.GL_UNSIGNED_BYTE,
                                     self.width, self.height)
        self.resize(camera.width, camera.height)
        GL.glClearColor(*scene.background, 1.0)
        GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)

        near, far = scene.clip_planes()
        GL.glMatrixMode(GL.GL_PROJECTION)
        GL.glLoadMatrixd(camera.projection_matrix(near, far).T)
        GL.glMatrixMode(GL.GL_MODELVIEW)
        GL.glLoadIdentity()
        # lights fixed to the camera: key light from above right behind the viewer, fill left
        GL.glLightfv(GL.GL_LIGHT0, GL.GL_POSITION, (0.3, 1.0, 0.45, 0.0))
        GL.glLightfv(GL.GL_LIGHT1, GL.GL_POSITION, (-0.6, -0.2, 0.8, 0.0))
        view = camera.view_matrix()
        GL.glLoadMatrixd(view.T)
        self._draw_grid(scene)

        items = scene.draw_list()
        GL.glEnable(GL.GL_LIGHTING)
        GL.glEnableClientState(GL.GL_VERTEX_ARRAY)
        GL.glEnableClientState(GL.GL_NORMAL_ARRAY)
        opaque = [item for item in items if item.color[3] >= 1.0]
        clear = [item for item in items if item.color[3] < 1.0]
        self._two_sided = self._normalize = None
        for item in opaque:
            self._draw_item(item, camera)
        if clear:
            GL.glEnable(GL.GL_BLEND)
            GL.glDepthMask(GL.GL_FALSE)
            for item in clear:
                self._draw_item(item, camera)
            GL.glDepthMask(GL.GL_TRUE)
            GL.glDisable(GL.GL_BLEND)
        GL.glBindBuffer(GL.GL_ARRAY_BUFFER, 0)
        GL.glDisableClientState(GL.GL_NORMAL_ARRAY)
        GL.glDisableClientState(GL.GL_VERTEX_ARRAY)
        GL.glDisable(GL.GL_LIGHTING)
        self._forget_meshes_not_in({item.geometry.key for item in items})
        return self.read_pixels()

    def _draw_item(self, item, camera) -> None:
        geometry = item.geometry
        if geometry.kind == "mesh":
            level, vertices, normals, indices = geometry.detail(self._pixel_size(item, camera)
                                                                * LOD_PIXELS)
            buffer = self._meshes.get((geometry.key, level))
            if buffer is None:
                buffer = self._meshes[geometry.key, level] = _Buffer(vertices, normals, indices)
                self.uploads += 1
        else:
            buffer = self._primitives[geometry.kind]
        self._set_sides(not geometry.closed)
        self._set_normalize(geometry.scale_B != (1.0, 1.0, 1.0))
        GL.glColor4d(*item.color)
        GL.glPushMatrix()
        GL.glMultMatrixd(np.ascontiguousarray(item.model_W.T))
        buffer.draw()
        GL.glPopMatrix()

    @staticmethod
    def _pixel_size(item, camera) -> float:
        """m: the side of a pixel at the point of the item's bounding sphere nearest the eye
        (a millimetre at most inside the sphere: the eye among the geometry sees it whole)."""
        distance = float(np.linalg.norm(np.subtract(camera.eye_W, item.model_W[:3, 3])))
        nearest = max(distance - item.geometry.radius, 1e-3)
        return 2.0 * nearest * math.tan(camera.fov_y / 2) / camera.height

    def _set_sides(self, two_sided: bool) -> None:
        """Closed outward surfaces: cull back faces, light the front. Open or inverted ones
        (many Kautham meshes): draw and light both sides. Costs ~10 ms a frame on llvmpipe for
        the grasp scene, hence per object."""
        if two_sided == self._two_sided:
            return
        self._two_sided = two_sided
        GL.glLightModeli(GL.GL_LIGHT_MODEL_TWO_SIDE, GL.GL_TRUE if two_sided else GL.GL_FALSE)
        if two_sided:
            GL.glDisable(GL.GL_CULL_FACE)
        else:
            GL.glEnable(GL.GL_CULL_FACE)

    def _set_normalize(self, scaled: bool) -> None:
        """Re-normalise normals only for scaled primitives (meshes have unit normals)."""
        if scaled == self._normalize:
            return
        self._normalize = scaled
        (GL.glEnable if scaled else GL.glDisable)(GL.GL_NORMALIZE)

    def _draw_grid(self, scene: Scene) -> None:
        grid = scene.grid()
        cx, cy = grid.centre_xy
        n = int(round(grid.half_size / grid.spacing))
        ticks = np.arange(-n, n + 1) * grid.spacing
        lines = []
        for t in ticks:
            lines += [(cx + t, cy - grid.half_size, 0.0), (cx + t, cy + grid.half_size, 0.0),
                      (cx - grid.half_size, cy + t, 0.0), (cx + grid.half_size, cy + t, 0.0)]
        shade = np.asarray(scene.background) * 0.78
        GL.glColor3d(*shade)
        GL.glLineWidth(1.0)
        GL.glEnableClientState(GL.GL_VERTEX_ARRAY)
        GL.glVertexPointer(3, GL.GL_DOUBLE, 0, np.ascontiguousarray(lines, dtype=np.float64))
        GL.glDrawArrays(GL.GL_LINES, 0, len(lines))
        GL.glDisableClientState(GL.GL_VERTEX_ARRAY)

    def _forget_meshes_not_in(self, keys: set) -> None:
        for key in [k for k in self._meshes if k[0] not in keys]:
            self._meshes.pop(key).delete()

    @property
    def mesh_buffers(self) -> int:
        """Meshes (each level of detail drawn counts) held on the GPU now."""
        return len(self._meshes)

    def read_pixels(self) -> np.ndarray:
        """The framebuffer as (height, width, 3) uint8 RGB, row 0 at the top."""
        GL.glFinish()
        data = GL.glReadPixels(0, 0, self.width, self.height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
        frame = np.frombuffer(data, dtype=np.uint8).reshape(self.height, self.width, 3)
        return np.ascontiguousarray(frame[::-1])
