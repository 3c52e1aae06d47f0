"""Every owner frees its ODE handle exactly once; removals and New Scene free everything."""
import collections
import gc

import numpy as np
import pytest

from virtual_world import core as vc
from virtual_world.ode import handles
from virtual_world.core import CompositeSpec, Core, JointSpec, MotorSpec, ObjectSpec, PartSpec
from virtual_world.ode.bindings import ffi, lib
from virtual_world.ode.runtime import drain_messages

BOX_V = [x for c in [(-.1, -.1, -.1), (.1, -.1, -.1), (-.1, .1, -.1), (.1, .1, -.1),
                     (-.1, -.1, .1), (.1, -.1, .1), (-.1, .1, .1), (.1, .1, .1)] for x in c]
BOX_I = [0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2,
         1, 3, 7, 1, 7, 5]


@pytest.fixture
def spy(monkeypatch):
    """Counts every destroy call per (kind, address) while still freeing."""
    freed = collections.Counter()
    for kind, destroy in list(handles.DESTROYERS.items()):
        def wrapper(ptr, kind=kind, destroy=destroy):
            freed[(kind, int(ffi.cast("uintptr_t", ptr)))] += 1
            destroy(ptr)
        monkeypatch.setitem(handles.DESTROYERS, kind, wrapper)
    return freed


def kinds(freed):
    return collections.Counter(kind for kind, _ in freed)


def frees(freed):
    """Destroy calls per kind (addresses may be reused)."""
    counts = collections.Counter()
    for (kind, _), count in freed.items():
        counts[kind] += count
    return counts


def build_scene(core):
    core.build_object(ObjectSpec("ground", [4, 4, 1], position=(0, 0, -0.5), geometry_only=True))
    core.build_object(ObjectSpec("s", [0.1], position=(0, 0, 1)))
    core.build_object(ObjectSpec("mesh", BOX_V, BOX_I, position=(1, 0, 1)))
    core.build_composite(CompositeSpec([PartSpec("p1", [0.1]),
                                        PartSpec("p2", [0.1, 0.1, 0.1], position=(0.3, 0, 0))],
                                       position=(2, 0, 1)))
    core.add_joint(JointSpec(vc.HINGE, "s", "mesh", anchor=(0.5, 0, 1)))
    core.add_motor(MotorSpec(joint="1:s&mesh"))
    core.add_joint(JointSpec(vc.BALL, ">p1>p2", "", anchor=(2, 0, 1)))
    core.add_body_force("s", vc.FORCE, (0, 0, 1))
    core.add_joint_force("1:s&mesh", [0.1])
    core.step(0.001, 10)


def test_owner_frees_once_and_children_first(spy):
    world = handles.new_world()
    body = handles.new_body(world)
    joint = handles.new_joint(world, vc.BALL, [body])
    body.close()  # closes the joint attached to it first
    assert joint.closed and body.closed and not world.closed
    body.close()
    joint.close()
    world.close()
    world.close()
    assert kinds(spy) == {"world": 1, "body": 1, "joint": 1}
    assert all(count == 1 for count in spy.values())
    with pytest.raises(ValueError):
        world.ptr


def test_forgotten_owner_is_freed_once_by_gc(spy):
    world = handles.new_world()
    body = handles.new_body(world)
    del world  # the body keeps its world alive
    gc.collect()
    assert not spy
    del body
    gc.collect()
    assert kinds(spy) == {"world": 1, "body": 1}


def test_trimesh_owner_keeps_arrays_and_frees_data_after_geom(spy):
    space = handles.new_space()
    vertices = np.array(BOX_V, dtype=float).reshape(-1, 3)
    indices = np.array(BOX_I, dtype=np.uint32).reshape(-1, 3)
    geom = handles.new_trimesh(space, vertices, indices, serial=1)
    order = []
    spy_keys = list(spy)
    del vertices, indices
    gc.collect()
    assert not spy
    geom.close()
    order = [kind for kind, _ in spy]
    assert order == ["geom", "trimeshdata"]
    space.close()
    assert kinds(spy) == {"geom": 1, "trimeshdata": 1, "space": 1}
    assert spy_keys == []


def test_remove_object_frees_its_handles_and_reports_ids(spy):
    core = Core()
    build_scene(core)
    spy.clear()
    removed = core.remove_object("mesh")
    assert removed == vc.Removed(("1:s&mesh",), ("motor:1:s&mesh",),
                                 ("jointforce:1:s&mesh:0",), ("mesh",))
    assert kinds(spy) == {"joint": 2, "geom": 1, "body": 1}   # its trimesh data kept idle
    spy.clear()
    removed = core.remove_object(">p1>p2")
    assert removed.geometries == ("p1", "p2") and removed.joints == ("0:>p1>p2&",)
    assert kinds(spy) == {"joint": 1, "geom": 2, "body": 1}
    assert core.poses()[0] == ["ground", "s"]
    core.step(0.001, 10)
    core.close()


def test_new_scene_and_close_free_everything_once(spy):
    core = Core()
    build_scene(core)
    core.new_scene()  # the mesh's trimesh data is kept for the next scene
    assert kinds(spy) == {"world": 1, "space": 1, "jointgroup": 1, "body": 3, "geom": 5,
                          "joint": 3}
    assert all(count == 1 for count in spy.values())
    assert core.poses()[0] == [] and core.object_ids() == [] and core.sim_time == 0.0
    assert core.joint_ids() == [] and core.motor_ids() == [] and core.body_force_ids() == []
    build_scene(core)  # the same names are free again
    spy.clear()
    core.close()
    core.close()
    assert kinds(spy) == {"world": 1, "space": 1, "jointgroup": 1, "body": 3, "geom": 5,
                          "trimeshdata": 1, "joint": 3}
    assert all(count == 1 for count in spy.values())


def box_mesh():
    return (np.array(BOX_V, dtype=float).reshape(-1, 3),
            np.array(BOX_I, dtype=np.uint32).reshape(-1, 3))


def test_geoms_over_the_same_mesh_share_one_trimesh_data(spy):
    space, cache = handles.new_space(), handles.TriMeshDataCache()
    vertices, triangles = box_mesh()
    first = handles.new_trimesh(space, vertices, triangles, serial=1, meshes=cache)
    second = handles.new_trimesh(space, vertices.copy(), triangles.copy(), serial=2,
                                 meshes=cache)
    other = handles.new_trimesh(space, vertices * 2, triangles, serial=3, meshes=cache)
    assert cache.builds == 2 and cache.sizes == (2, 0)
    def data(geom):
        return geom._handle.keep[0].data.address      # the lease the geom holds

    assert data(first) == data(second) != data(other)
    first.close()
    assert kinds(spy) == {"geom": 1} and cache.sizes == (2, 0)   # the second still uses it
    second.close()
    other.close()
    assert kinds(spy) == {"geom": 3} and cache.sizes == (2, 2)   # idle, kept
    cache.close()
    assert kinds(spy) == {"geom": 3, "trimeshdata": 2} and cache.sizes == (0, 0)
    assert all(count == 1 for count in spy.values())
    space.close()


def test_trimesh_data_no_geom_uses_is_freed_beyond_the_idle_budget(spy):
    space, cache = handles.new_space(), handles.TriMeshDataCache(idle_triangles=12)
    vertices, triangles = box_mesh()                                # 12 triangles each
    geoms = [handles.new_trimesh(space, vertices * (k + 1), triangles, serial=k + 1,
                                 meshes=cache) for k in range(3)]
    geoms[0].close()
    assert kinds(spy) == {"geom": 1} and cache.sizes == (3, 1)
    geoms[1].close()                               # 24 idle triangles: the oldest goes
    assert frees(spy) == {"geom": 2, "trimeshdata": 1} and cache.sizes == (2, 1)
    again = handles.new_trimesh(space, vertices * 2, triangles, serial=4, meshes=cache)
    assert cache.builds == 3 and cache.sizes == (2, 0)             # the idle one, reused
    cache.close()                                  # still leased: freed after its last geom
    assert frees(spy) == {"geom": 2, "trimeshdata": 1}
    again.close()
    geoms[2].close()
    assert frees(spy) == {"geom": 4, "trimeshdata": 3} and cache.sizes == (0, 0)
    space.close()


def test_new_scene_reuses_the_trimesh_data_and_collides_as_a_fresh_world():
    def drop_on_mesh(core):
        core.build_object(ObjectSpec("mesh", BOX_V, BOX_I, position=(0, 0, 0),
                                     geometry_only=True))
        core.build_object(ObjectSpec("ball", [0.05], position=(0.02, 0.01, 0.3)))
        core.step(0.001, 600)
        return core.body_state("ball")

    fresh = Core()
    expected = drop_on_mesh(fresh)
    fresh.close()
    core = Core()
    drop_on_mesh(core)
    core.new_scene()
    again = drop_on_mesh(core)
    assert core._meshes.builds == 1
    assert again[0][2] == pytest.approx(0.15, abs=2e-3)             # resting on the box
    for got, want in zip(again, expected):
        np.testing.assert_array_equal(got, want)                   # bit for bit
    core.close()


def test_new_scene_keeps_world_parameters():
    core = Core()
    core.set_world_parameters(gravity=(0, 0, -1), max_contacts=5)
    core.new_scene()
    assert core.world_parameters.gravity == (0, 0, -1) and core._scene.c.max_contacts == 5
    core.build_object(ObjectSpec("s", [0.1]))
    core.step(0.01, 100)
    assert core.body_state("s")[2][2] == pytest.approx(-1.0)
    core.close()


def test_removal_mid_contact_less_keeps_other_pairs():
    core = Core()
    core.set_world_parameters(gravity=(0, 0, 0), contact_less=True)
    for i, x in enumerate((0, 0.15, 0.3)):
        core.build_object(ObjectSpec(f"s{i}", [0.1], position=(x, 0, 0)))
    core.step(0.001)
    core.remove_object("s2")
    assert [(c.first, c.second) for c in core.read_collisions()] == [("s0", "s1")]
    core.close()


def test_poses_are_cheap_arrays():
    core = Core()
    for i in range(1000):
        core.build_object(ObjectSpec(f"s{i}", [0.1], position=(i, 0, 0)))
    names, positions, quaternions = core.poses()
    assert len(names) == 1000 and positions.shape == (1000, 3) and quaternions.shape == (1000, 4)
    np.testing.assert_allclose(positions[:, 0], np.arange(1000))
    core.close()


def test_ode_messages_are_drained_into_logging(caplog):
    Core().close()  # installs the handlers
    lib.odin_test_message(7, b"hello from ODE")
    with caplog.at_level("WARNING", logger="virtual_world.core"):
        assert drain_messages() == ["hello from ODE"]
    assert "hello from ODE" in caplog.text
    assert drain_messages() == []


def test_what_ode_says_during_a_request_is_logged_before_the_request_returns(caplog):
    core = Core()
    core.build_object(ObjectSpec("ball", [0.1], position=(0, 0, 1)))
    lib.odin_test_message(7, b"said during the step")   # as if dWorldStep had spoken
    with caplog.at_level("WARNING", logger="virtual_world.core"):
        core.step(0.01)
    assert "said during the step" in caplog.text
    assert drain_messages() == []                      # the ode layer drained it
    core.close()


def test_a_core_dropped_in_a_reference_cycle_is_freed_children_first(spy):
    """The collector finalizes a whole unreachable scene at once, in no set order: the world
    still goes last (it used to go first, and its bodies' dBodyDestroy then crashed)."""
    for _ in range(3):
        core = Core()
        build_scene(core)
        cycle = [core]
        cycle.append(cycle)
        del core, cycle
        gc.collect()
    counts = collections.Counter()
    for (kind, _), count in spy.items():      # addresses are reused from scene to scene
        counts[kind] += count
    assert counts["world"] == 3 and counts["body"] == 3 * 3 and counts["geom"] == 3 * 5
