"""What the explorer's server lets in, decided without a server: :class:`~brakesqueal.explorer.server.Guard`, the
link limits of :func:`~brakesqueal.explorer.state.link_problem` and the address check (issue 30).

Randomised (seeded) over host names, ports, origins, tokens and link values; the served behaviour is in
``test_server_security.py`` and ``test_browser_security.py``.
"""

from __future__ import annotations

import random
import string

import pytest
from tornado.httputil import HTTPHeaders, HTTPServerRequest, RequestStartLine

from brakesqueal import resolve_space
from brakesqueal.errors import ParameterError
from brakesqueal.explorer.server import Guard, check_address, explorer_url, is_loopback
from brakesqueal.explorer.state import (
    LINK_KEYS,
    MAX_LINK_PARAMS,
    MAX_LINK_SET,
    MAX_LINK_VALUE,
    Origin,
    ViewState,
    link_limit_message,
    link_problem,
)

PORT = 47123
TOKEN = "t0k3n-" + "x" * 37


def request(host: str | None = f"127.0.0.1:{PORT}", *, uri: str = "/", origin: str | None = None,
            cookie: str | None = None, fetch: tuple[str, str, str] | None = None) -> HTTPServerRequest:
    """A request as Tornado hands it to the router (``fetch``: Sec-Fetch-Site, -Mode, -Dest)."""
    headers = HTTPHeaders()
    if host is not None:
        headers["Host"] = host
    if origin is not None:
        headers["Origin"] = origin
    if cookie is not None:
        headers["Cookie"] = cookie
    if fetch is not None:
        headers["Sec-Fetch-Site"], headers["Sec-Fetch-Mode"], headers["Sec-Fetch-Dest"] = fetch
    return HTTPServerRequest(start_line=RequestStartLine("GET", uri, "HTTP/1.1"), headers=headers)


LOCAL = Guard.for_address("127.0.0.1", PORT, TOKEN)
REMOTE = Guard.for_address("0.0.0.0", PORT, TOKEN, remote=True)
WITH_TOKEN = f"/?token={TOKEN}"
COOKIE = f"{LOCAL.cookie}={TOKEN}"


def random_name(rng: random.Random) -> str:
    """A DNS name that is not loopback (an attacker's, rebound to this machine)."""
    label = "".join(rng.choice(string.ascii_lowercase) for _ in range(rng.randint(1, 12)))
    return f"{label}.{rng.choice(['example', 'com', 'internal', 'localhost.example'])}"


@pytest.mark.parametrize("host", ["127.0.0.1", "localhost", "[::1]", "LOCALHOST"])
def test_loopback_names_with_the_token_are_let_in(host):
    assert LOCAL.refusal(request(f"{host}:{PORT}", uri=WITH_TOKEN)) is None
    assert LOCAL.refusal(request(f"{host}:{PORT}", cookie=COOKIE)) is None
    assert LOCAL.refusal(request(f"{host}:{PORT}", uri=WITH_TOKEN, origin=f"http://{host}:{PORT}")) is None


def test_a_host_that_is_not_this_server_is_refused_even_with_the_token():
    # DNS rebinding: the attacker's name resolves to 127.0.0.1, so its page is same-origin with the server;
    # only the Host header tells (Tornado does not check the Origin when it equals the Host)
    rng = random.Random(30)
    for _ in range(200):
        name = random_name(rng)
        port = rng.choice([PORT, PORT + 1, 80, rng.randint(1, 65535)])
        host = f"{name}:{port}"
        why = LOCAL.refusal(request(host, uri=WITH_TOKEN, origin=f"http://{host}", cookie=COOKIE))
        assert why is not None and "Host" in why
        assert REMOTE.refusal(request(host, uri=WITH_TOKEN, origin=f"http://{host}", cookie=COOKIE)) is not None
    for host in ("", f"127.0.0.1:{PORT + 1}", "127.0.0.1", f"127.0.0.2:{PORT}", f"0.0.0.0:{PORT}",
                 f"[::]:{PORT}", f"localhost.:{PORT}", f"127.0.0.1.evil.example:{PORT}"):
        assert LOCAL.refusal(request(host, uri=WITH_TOKEN)) is not None, host


def test_an_origin_other_than_the_host_is_refused():
    rng = random.Random(31)
    for _ in range(200):
        origin = rng.choice([f"http://{random_name(rng)}:{PORT}", f"http://127.0.0.1:{rng.randint(1, 65535)}",
                             f"https://127.0.0.1:{PORT}", "null", f"http://localhost:{PORT}"])
        if origin == f"http://localhost:{PORT}":  # another loopback name than the Host's: another origin
            assert LOCAL.refusal(request(f"127.0.0.1:{PORT}", uri=WITH_TOKEN, origin=origin)) is not None
            continue
        if origin == f"http://127.0.0.1:{PORT}":
            continue
        assert LOCAL.refusal(request(uri=WITH_TOKEN, origin=origin, cookie=COOKIE)) == \
            "requests from another origin are refused"


def test_the_token_is_needed_in_the_query_or_the_cookie():
    rng = random.Random(32)
    assert "token" in (LOCAL.refusal(request()) or "")
    for _ in range(100):
        wrong = TOKEN[:-1] + rng.choice("abc") if rng.random() < 0.5 else "".join(
            rng.choice(string.ascii_letters) for _ in range(rng.randint(0, 60)))
        assert LOCAL.refusal(request(uri=f"/?token={wrong}")) is not None
        assert LOCAL.refusal(request(cookie=f"{LOCAL.cookie}={wrong}")) is not None
    # the cookie of another port's explorer (browsers share cookies across ports) is not this one's
    assert LOCAL.refusal(request(cookie=f"brakesqueal-explorer-{PORT + 1}={TOKEN}")) is not None
    assert LOCAL.refusal(request(uri=f"/static/js/bokeh.min.js?token={TOKEN}")) is None
    assert LOCAL.refusal(request(uri="/ws", cookie=f"other=1; {COOKIE}")) is None


def test_requests_a_browser_marks_as_from_another_site_are_refused_unless_a_navigation_with_the_token():
    for site in ("cross-site", "same-site"):
        for mode, dest in (("cors", "empty"), ("no-cors", "image"), ("no-cors", "script"), ("websocket", "empty"),
                           ("navigate", "iframe")):
            assert LOCAL.refusal(request(uri=WITH_TOKEN, cookie=COOKIE, fetch=(site, mode, dest))) is not None
        # a link from another site: the page opens only with the token in the URL (the cookie is not enough)
        assert LOCAL.refusal(request(cookie=COOKIE, fetch=(site, "navigate", "document"))) is not None
        assert LOCAL.refusal(request(uri=WITH_TOKEN, fetch=(site, "navigate", "document"))) is None
    for site in ("same-origin", "none"):
        assert LOCAL.refusal(request(cookie=COOKIE, fetch=(site, "cors", "empty"))) is None


def test_the_cookie_is_strict_http_only_and_named_with_the_port():
    header = LOCAL.set_cookie_header()
    assert header.startswith(f"brakesqueal-explorer-{PORT}={TOKEN};")
    assert "HttpOnly" in header and "SameSite=Strict" in header


def test_remote_binding_accepts_addresses_not_names():
    assert REMOTE.refusal(request(f"192.168.1.20:{PORT}", uri=WITH_TOKEN)) is None
    assert REMOTE.refusal(request(f"[fe80::1]:{PORT}", uri=WITH_TOKEN)) is None
    assert REMOTE.refusal(request(f"192.168.1.20:{PORT}")) is not None  # still the token
    assert REMOTE.refusal(request(f"192.168.1.20:{PORT}", uri=WITH_TOKEN,
                                  origin=f"http://evil.example:{PORT}")) is not None  # still the origin
    assert REMOTE.refusal(request(f"evil.example:{PORT}", uri=WITH_TOKEN)) is not None


def test_the_url_carries_the_token():
    assert explorer_url("127.0.0.1", PORT, TOKEN) == f"http://127.0.0.1:{PORT}/?token={TOKEN}"
    assert explorer_url("0.0.0.0", PORT, TOKEN).startswith(f"http://127.0.0.1:{PORT}/?token=")
    assert explorer_url("::1", PORT, TOKEN).startswith(f"http://[::1]:{PORT}/")


@pytest.mark.parametrize("host", ["0.0.0.0", "::", "192.168.1.20", "example.org", "10.0.0.1"])
def test_binding_beyond_loopback_needs_allow_remote(host):
    assert not is_loopback(host)
    with pytest.raises(ParameterError) as err:
        check_address(host, 5006, allow_remote=False)
    text = str(err.value)
    assert "\n" not in text and "--host" in text and "--allow-remote" in text
    check_address(host, 5006, allow_remote=True)
    check_address("127.0.0.1", 5006, allow_remote=False)
    check_address("localhost", 5006, allow_remote=False)


# ------------------------------------------------------------------------------------------ link limits
def test_links_within_the_limits_pass():
    assert link_problem({}) is None
    assert link_problem({"preset": ["paper-fig2"], "set": ["mu=0.3,k_ip=1e7"], "nx": ["400"], "token": [TOKEN]}) is None
    long_set = ",".join(f"n{i}={'9' * MAX_LINK_VALUE}" for i in range(MAX_LINK_SET // (MAX_LINK_VALUE + 6)))
    assert len(long_set) <= MAX_LINK_SET and link_problem({"set": [long_set]}) is None


def test_links_beyond_the_limits_name_the_parameter():
    rng = random.Random(33)
    for _ in range(300):
        key = rng.choice(LINK_KEYS)
        kind = rng.choice(["long", "nonascii", "control"])
        if kind == "long":
            n = rng.randint((MAX_LINK_SET if key == "set" else MAX_LINK_VALUE) + 1, 100_000)
            value = rng.choice("0123456789") * n
        elif kind == "nonascii":
            value = rng.choice(["²", "٣", "١٢٣", "x\u200b", "é"])  # str.isdigit() accepts some: Panel int()s them
        else:
            value = "1" + rng.choice(["\n", "\x00", "\t", "\x7f"])
        assert link_problem({key: [value], "nx" if key != "nx" else "ny": ["400"]}) == key
    assert link_problem({"x" * (MAX_LINK_VALUE + 1): ["1"]}) == "link"
    assert link_problem({"other": ["5" * 5000]}) == "link"
    assert link_problem({f"k{i}": ["1"] for i in range(MAX_LINK_PARAMS + 1)}) == "link"
    assert link_problem({"set": [f"mu={'1' * (MAX_LINK_VALUE + 1)}"]}) == "set"


def test_a_5000_digit_number_in_a_link_is_one_line_without_the_value():
    default = ViewState(model="paper", preset="paper-fig2")
    for key in ("nx", "ny", "t_end"):
        with pytest.raises(ParameterError) as err:
            ViewState.from_query({key: "5" * 5000}, default)
        text = str(err.value)
        assert "\n" not in text and f"'{key}'" in text and str(MAX_LINK_VALUE) in text and len(text) < 300
    assert "\n" not in link_limit_message("link")


def test_values_within_the_limits_still_reach_the_checks():
    origin = Origin(resolve_space(None, "paper-fig2", None, []))
    st = ViewState.from_query({"nx": "9" * MAX_LINK_VALUE}, origin.initial_state())
    assert st.nx == int("9" * MAX_LINK_VALUE)  # refused later by the map's cap, with its own message


@pytest.mark.parametrize("token", ["short", "x" * 15, "a;b" * 8, "tök" * 8, "t" * 257, "a b" * 8])
def test_a_malformed_token_is_refused_before_serving(token):
    from brakesqueal.explorer.server import make_server

    with pytest.raises(ParameterError) as err:
        make_server(resolve_space(None, "paper-fig2", None, []), port=0, token=token)
    assert "token" in str(err.value) and "\n" not in str(err.value) and token not in str(err.value)
