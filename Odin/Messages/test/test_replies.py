"""odin_common.replies: how every Portal turns a handler's outcome into a service response."""
import logging
from types import SimpleNamespace

from odin_common import InvalidArgument
from odin_common.replies import guarded


class Response(SimpleNamespace):
    """Stands in for a generated response class: keyword fields in, attributes out."""


SERVICE = SimpleNamespace(_response_class=Response, _type="Services/Example")


def test_a_handler_that_returns_answers_success_with_its_fields():
    answer = guarded(SERVICE, lambda request: {"message": f"got {request}", "count": 2})
    assert answer(7) == Response(success=True, message="got 7", count=2)


def test_a_refusal_answers_its_message_and_the_values_in_force():
    def refuse(request):
        raise InvalidArgument("erp=2 is out of [0, 1]")
    answer = guarded(SERVICE, refuse, in_force=lambda: {"erp": 0.2})
    assert answer(None) == Response(success=False, message="erp=2 is out of [0, 1]", erp=0.2)


def test_a_bug_is_answered_as_an_internal_error_and_logged_with_its_traceback(caplog):
    def fail(request):
        raise ValueError("no such thing")
    with caplog.at_level(logging.ERROR, logger="rosout"):
        response = guarded(SERVICE, fail)(None)
    assert response == Response(success=False,
                                message="internal error: ValueError: no such thing")
    assert "Services/Example failed" in caplog.text and "Traceback" in caplog.text
