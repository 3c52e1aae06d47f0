"""Calling a node's services by name: the one place the GUI's clients (``WorldClient``,
``ViewerClient``, ``WorldPool``), the soak tool and the node tests make a rospy service call.

A ``ServiceCaller`` serves one node's namespace and its {service name: srv type name} table
(``odin_common.interface.WORLD_SERVICES``, ``VIEWER_SERVICES``). It keeps one proxy per
service, persistent unless told otherwise (a round trip is ~0.05 ms persistent against ~1.2 ms
fresh), drops it after a broken call so that the next call connects again, and translates
every failure once into its ``error`` type (``gui.errors.ServiceError`` or a subclass) carrying
the service's path and the message: a broken call ("call failed: ..."), a refusal
(``success: false``, from ``call`` only: ``ask`` returns a refused answer) and a service not
registered in time (``wait``).

rospy's proxies are not shared between threads: one caller per thread. Requires
``rospy.init_node`` (``join_ros_graph`` does it unless done); importing this module does not
import rospy.
"""
from __future__ import annotations

import contextlib
import logging
import time
import xmlrpc.client
from typing import Dict, Iterator, Mapping, Type

from gui.errors import ServiceError
from odin_common.master_link import TimeoutTransport

PING_TIMEOUT = 2.0      # s: a node that does not answer its pid in this long is absent


def join_ros_graph(node_name: str) -> None:
    """This process as the anonymous ROS node ``node_name`` (without rospy's signal handlers:
    the caller's tool or window handles Ctrl-C), unless it is a node already."""
    import rospy
    if not rospy.core.is_initialized():
        with _prompt_registration():
            rospy.init_node(node_name, anonymous=True, disable_signals=True)
        from odin_common.node import prompt_shutdown
        prompt_shutdown()


class _PollingTime:
    """The ``time`` module as rospy.impl.init sees it during ``_prompt_registration``: every
    sleep at most REGISTRATION_POLL s."""

    def __getattr__(self, name: str):
        return getattr(time, name)

    @staticmethod
    def sleep(seconds: float) -> None:
        time.sleep(min(seconds, REGISTRATION_POLL))


#: s between two looks at whether the master registered this node (rospy's own: 0.1 s)
REGISTRATION_POLL = 0.002


@contextlib.contextmanager
def _prompt_registration() -> Iterator[None]:
    """rospy.init_node waits for the node's registration with the master by looking every
    0.1 s, and the first look always comes before the registration (a few ms, on the node's
    XML-RPC thread): every tool's start waited 0.1 s for nothing (python3-rospy 1.15,
    rospy.impl.init.start_node). Within the block it looks every REGISTRATION_POLL s."""
    from rospy.impl import init
    module_time = init.time
    init.time = _PollingTime()
    try:
        yield
    finally:
        init.time = module_time


class _WaitingNoise(logging.Filter):
    """Drops rospy.wait_for_service's "failed to contact, will keep trying" (and its "finally
    were able to contact"): a node killed stays registered with the master, and rospy says so
    on stderr every 10 s while it waits, around the one line a tool ends with (the wait's
    outcome is said by ``ServiceCaller.wait``'s error)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith("wait_for_service(")


_WAITING_NOISE = _WaitingNoise()


def _quiet_waits() -> None:
    """Puts ``_WaitingNoise`` on rospy's logger (once: a logger keeps a filter once)."""
    logging.getLogger("rosout").addFilter(_WAITING_NOISE)


class ServiceCaller:
    """Calls ``<namespace>/<service>`` for the services of ``services`` ({name: srv type name
    in the Services package}); failures raise ``error(service path, message)``."""

    def __init__(self, namespace: str, services: Mapping[str, str],
                 error: Type[ServiceError] = ServiceError, persistent: bool = True):
        import rospy
        from Services import srv
        self._rospy = rospy
        self._srv = srv
        self.namespace = namespace.rstrip("/")
        self.services = services
        self.error = error
        self.persistent = persistent
        self._proxies: Dict[str, object] = {}

    def path(self, service: str) -> str:
        """The service's full name: ``<namespace>/<service>``."""
        return f"{self.namespace}/{service}"

    def wait(self, service: str, timeout: float, absent: str) -> None:
        """Waits up to ``timeout`` s for ``service`` to be registered; raises
        ``error(namespace, absent)`` if it is not. Quietly: rospy's own word on a registered
        service whose node does not answer (``_WaitingNoise``) is left out."""
        _quiet_waits()
        try:
            self._rospy.wait_for_service(self.path(service), timeout=timeout)
        except self._rospy.ROSException:
            raise self.error(self.namespace, absent) from None

    def call(self, service: str, /, **fields):
        """Calls one service with request ``fields``; returns the response, or raises ``error``
        if the call broke or the node refused (``success: false``)."""
        return self._accepted(service, self.ask(service, **fields))

    def send(self, service: str, request):
        """``call`` with a request message made beforehand: an instance of the service's
        request class (or of a subclass that serialises itself faster)."""
        return self._accepted(service, self._exchange(service, lambda request_class: request))

    def ask(self, service: str, /, **fields):
        """Calls one service and returns its response, refused or not (a refused Set Step or
        Set Camera still reports the values in force); raises ``error`` only if the call
        breaks (node gone, connection dropped), after dropping its proxy."""
        return self._exchange(service, lambda request_class: request_class(**fields))

    def _accepted(self, service: str, response):
        if not response.success:
            raise self.error(self.path(service), response.message)
        return response

    def _exchange(self, service: str, make_request):
        """The response to ``make_request(request class)``; a broken call raises ``error``."""
        proxy = self._proxies.get(service)
        if proxy is None:
            service_class = getattr(self._srv, self.services[service])
            proxy = self._rospy.ServiceProxy(self.path(service), service_class,
                                             persistent=self.persistent)
            self._proxies[service] = proxy
        try:
            return proxy(make_request(proxy.request_class))
        except (self._rospy.ServiceException, OSError) as error:
            self._proxies.pop(service, None)
            raise self.error(self.path(service), f"call failed: {error}") from None

    def close(self) -> None:
        """Closes every proxy (the next call connects again)."""
        for proxy in self._proxies.values():
            proxy.close()
        self._proxies.clear()


def node_answers(service: str, caller_id: str = "/gui") -> bool:
    """Whether ``service`` (a full name) is registered AND its node answers: a node that
    crashed (SIGKILL, a segfault) never unregisters, so the master alone would call it alive.
    The node is asked its pid over its XML-RPC API, as ``rosnode ping`` does, giving up after
    PING_TIMEOUT s (a hung node is an absent one). ``caller_id``: who asks, when this process
    is no ROS node yet."""
    import rosgraph
    import rospy
    try:
        master = rosgraph.Master(rospy.get_name() or caller_id)
        providers = dict(master.getSystemState()[2]).get(service, [])
        if not providers:
            return False
        api = master.lookupNode(providers[0])
        xmlrpc.client.ServerProxy(api, transport=TimeoutTransport(PING_TIMEOUT)).getPid(
            master.caller_id)
        return True
    except Exception:  # master down, service not registered, node gone or not answering
        return False

