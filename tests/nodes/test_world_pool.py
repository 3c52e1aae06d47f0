"""A pool of world nodes used as one (gui.ros.pool): the same scene in each, propagations
fanned out and gathered in order, every answer the one a single world gives (the worlds are
deterministic), a refusal reported with the world that refused."""
from __future__ import annotations

import pytest

pytestmark = pytest.mark.forked

NAMESPACES = ["/w0/virtual_world", "/w1/virtual_world"]


def _scene(pool_or_world_call) -> None:
    from world_client import box, sphere
    call = pool_or_world_call
    call("build_object", object=box("ground", (4, 4, 0.2), (0, 0, -0.1), geometry_only=True))
    for i in range(4):
        call("build_object", object=sphere(f"s{i}", 0.1, (0.04 * i, 0, 0.3 + 0.21 * i)))
    call("save_state", name="start")


def _requests():
    from Messages.msg import BodyForce
    return [dict(start="start", duration=0.2 + 0.05 * k,
                 forces=[BodyForce(object=f"s{k % 4}", kind=0, vector=[2.0 * k, 0.0, 0.0])])
            for k in range(6)]


def _states(response):
    return [(s.id, tuple(s.position), tuple(s.linear)) for s in response.states]


def test_a_pool_of_two_answers_in_order_as_one_world_does(ros_master):
    for namespace in ("/w0", "/w1"):
        ros_master.rosrun("VirtualWorld", "virtualWorld", f"__ns:={namespace}")
    for namespace in NAMESPACES:
        ros_master.wait_for_service(f"{namespace}/propagate")
    from gui.ros.pool import PoolError, WorldPool
    with WorldPool(NAMESPACES) as pool:
        _scene(lambda service, **fields: pool.broadcast(service, **fields))
        assert [r.success for r in pool.broadcast("get_world")] == [True, True]
        fanned = pool.propagate(_requests())
        with pytest.raises(PoolError, match="w[01]/virtual_world/propagate: .*nope"):
            pool.propagate([dict(start="nope", duration=0.1)])
    with WorldPool(NAMESPACES[:1]) as single:
        alone = single.propagate(_requests())
    assert [r.steps for r in fanned] == [200 + 50 * k for k in range(6)]
    assert [_states(r) for r in fanned] == [_states(r) for r in alone]
