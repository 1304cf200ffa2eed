"""The explorer's page: Panel widgets and Bokeh figures, linked to the library through :mod:`.state`.

One :class:`Explorer` per browser session.  Widgets change the
:class:`~.state.ViewState`; every change is validated (the command line's
resolution), written to the URL and handed to three lanes of work
(:class:`~.worker.LatestWorker`): the eigenvalues and root locus (fast, on
every slider move), the map with critical speeds and Hopf criticality
(recomputed only when their inputs change), and the simulation (on request,
cancellable).  A hidden element ``#bs-render`` counts the updates applied to
the page and carries the state they show, for tests and benchmarks.

The simulation and the limit cycles run in a child process of their lane
(:class:`~.worker.ChildProcess`), which *Cancel* kills.  Every text the page
shows that can hold a value from a link or an input is escaped into an HTML
pane (never Markdown), so a link cannot put a link or an image into the page.
"""

from __future__ import annotations

import contextlib
import html
import io
import json
import logging
import math
import threading
import time
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import replace
from functools import partial, wraps
from typing import TYPE_CHECKING, Any, Concatenate, Final, Literal, ParamSpec, TypeVar

import numpy as np

from ..errors import BrakesquealError, ParameterError
from ..plotting import MAP_PAD_ONLY, MAP_STABLE, MAP_UNSTABLE
from .state import (
    AUDIO_RATE,
    LINK_KEYS,
    MAX_MAP_POINTS,
    MAX_T_END,
    REFUSED_KEY,
    LocusView,
    MapView,
    Origin,
    RegionView,
    SimulationView,
    SliderRange,
    ViewState,
    check_t_end,
    critical_speed_text,
    cycles_view,
    format_eigenvalue,
    hopf_scan,
    hopf_text,
    link_limit_message,
    locus_lines,
    locus_file,
    locus_view,
    map_file,
    map_view,
    region_view,
    simulation_view,
    slider_names,
    slider_range,
)
from .worker import Cancelled, CannotSend, ChildProcess, LatestWorker

if TYPE_CHECKING:
    from bokeh.document import Document
    from bokeh.events import Event as BokehEvent
    from bokeh.layouts import Column
    from bokeh.plotting import figure as Figure
    from panel.viewable import Viewable
    from param.parameterized import Event
    from tornado.ioloop import IOLoop

    from ..analysis.modes import ModeTracks
    from ..model.parameters import ParameterSpace
    from .state import CyclesView

__all__ = ["Explorer", "build_page"]

_P = ParamSpec("_P")
_R = TypeVar("_R")
#: What a cached view depends on (compared with ``==``).
_Key = tuple[Any, ...]
#: The locus lane's result: the space, the view, and whether its path is complete.
_Locus = tuple["ParameterSpace", LocusView, bool]

log = logging.getLogger(__name__)

#: Seconds a session waits for the server's warm-up (:func:`warm_up`) before it serves a page whose root
#: locus follows from the locus lane (a cold start compiles the model's code for much longer).
WARM_WAIT_S = 1.5
#: Milliseconds the state must rest before it is written to the URL.
URL_DELAY_MS = 400
#: Milliseconds the state must rest before the critical speeds and the Hopf point are recomputed (longer than
#: the steps of a moving slider, so that their work and their update of the page stay off its path).
INFO_REST_MS = 250
_LOG_FORMAT = "return Number((10 ** tick).toPrecision(3)).toExponential();"
#: The map's fill colours (unstable, stable, no verdict): the command line's map figures' (green stable, red unstable).
_MAP_PALETTE = [MAP_UNSTABLE, MAP_STABLE, "#c8c8c8", MAP_PAD_ONLY]
#: Colours of the current point and of stable and unstable limit cycles: matplotlib's C0 and C3, as in the command
#: line's figures (stable cycles drawn in C0, unstable ones in C3).
_POINT, _CYCLE_STABLE, _CYCLE_UNSTABLE = "#1f77b4", "#1f77b4", "#d62728"
#: Hopf curves on the map by criticality (the command line's region figure: C0 supercritical, C3 subcritical), and
#: the fold-of-cycles curves.
_HOPF_COLOURS = {"supercritical": "#1f77b4", "subcritical": "#d62728"}
_HOPF_UNDECIDED, _FOLD_COLOUR = "#7f7f7f", "#9467bd"
#: Look of the message line (Bootstrap's "danger" alert, as Panel's Alert pane had).
_ALERT_STYLE = {"background-color": "#f8d7da", "color": "#721c24", "border": "1px solid #f5c6cb",
                "border-radius": "4px", "padding": "0.5em 1em"}
#: Render level of what moves with every slider step (the current point, its markers): Bokeh repaints only
#: the overlay layer of a plot when only overlay renderers changed, not its axes, grids and lines.  They have
#: no legend entries (an overlay repaint erases their legend glyphs); titles and the map's legend text name them.
_MOVING: Final = "overlay"
#: Widths [px] of the page's columns: the controls, each of the two views of a row, the texts beside the map.  With
#: Panel's margins the page is about 1,230 px wide: it fits a 1280 px screen without a horizontal scroll bar.
_LEFT, _HALF, _TEXTS = 360, 410, 400


def _fmt_value(v: float) -> str:
    return "inf" if math.isinf(v) else f"{v:.6g}"


def _label(space: ParameterSpace, name: str) -> str:
    unit = space.preset.unit(name)
    return f"{name} [{unit}]" if unit else name


#: Milliseconds Panel waits before it handles a change sent by the browser (its default is 50 ms, a third of
#: the slider's latency budget); the explorer's own lanes drop stale values, so no debounce is needed.
WIDGET_DEBOUNCE_MS = 1


def _undebounce(*widgets: Any) -> None:
    """Handle the browser's changes of ``widgets`` at once (Panel's ``_debounce`` class attribute, per widget)."""
    for w in widgets:
        if hasattr(w, "_debounce"):
            w._debounce = WIDGET_DEBOUNCE_MS


def _locus_key(space: ParameterSpace, state: ViewState, ranges: dict[str, SliderRange]) -> tuple[_Key, SliderRange]:
    """What the root locus along ``state.along`` depends on (everything but the value of ``along``), its range."""
    rng = ranges[state.along] if state.along in ranges else slider_range(space, state.along)
    defs = {k: str(v) for k, v in space.definitions().items() if k != state.along}
    return (state.model, state.preset, state.along, rng, tuple(sorted(defs.items()))), rng


def _map_key(space: ParameterSpace, state: ViewState) -> _Key:
    """What the map depends on (everything but the values of its axes)."""
    defs = {k: str(v) for k, v in space.definitions().items()}
    return (state.model, state.preset, state.x, state.y, state.nx, state.ny,
            tuple(sorted((k, v) for k, v in defs.items() if k not in (state.x, state.y))))


def _region_key(space: ParameterSpace, state: ViewState) -> _Key:
    """What the squeal region over the map depends on (the map's key without its grid)."""
    model, preset, x, y, _nx, _ny, defs = _map_key(space, state)
    return model, preset, x, y, defs


def _criticality_runs(x: np.ndarray, y: np.ndarray, crit: list[str]) -> list[tuple[np.ndarray, np.ndarray, str]]:
    """A Hopf curve cut into pieces of one criticality (neighbouring pieces share their end point)."""
    runs: list[tuple[np.ndarray, np.ndarray, str]] = []
    start = 0
    for i in range(1, len(crit) + 1):
        if i == len(crit) or crit[i] != crit[start]:
            stop = min(i + 1, len(crit))
            runs.append((x[start:stop], y[start:stop], crit[start]))
            start = i
    return runs


def _percent(fraction: float) -> int:
    """A progress fraction as a whole percentage, clipped to [0, 100]."""
    return int(100 * min(max(fraction, 0.0), 1.0))


def _with_axis(state: ViewState, key: str, name: str) -> ViewState:
    """``state`` with its axis ``key`` (``"along"``, ``"x"`` or ``"y"``) set to ``name``."""
    if key == "along":
        return replace(state, along=name)
    return replace(state, x=name) if key == "x" else replace(state, y=name)


class _WarmUp:
    """The root locus of the command line's view, computed while the server starts (:func:`warm_up`).

    The first session waits for it rather than computing it a second time, and puts it into its page.
    """

    def __init__(self) -> None:
        self.started = False
        self.done = threading.Event()
        self.key: _Key | None = None
        self.tracks: ModeTracks | None = None

    def tracks_for(self, key: _Key, timeout: float = 60.0) -> ModeTracks | None:
        """The warmed-up modes along the path if ``key`` is the warmed-up view's, else None."""
        if not self.started:
            return None
        self.done.wait(timeout)
        return self.tracks if self.done.is_set() and key == self.key else None


_WARM = _WarmUp()


def warm_up(origin: Origin) -> None:
    """Start computing the command line's first view in a thread (loads the model's compiled code and the
    plotting modules while the server starts and the browser loads the page's scripts)."""
    _WARM.started = True

    def run() -> None:
        try:
            from bokeh.plotting import figure  # noqa: F401  (the first session's figures)

            state = origin.initial_state()
            space = origin.space_of(state)
            key, rng = _locus_key(space, state, {})
            lv = locus_view(space, state.along, rng)
            _WARM.key, _WARM.tracks = key, lv.tracks
        except Exception:  # the page reports the error itself
            log.debug("warm-up failed", exc_info=True)
        finally:
            _WARM.done.set()

    threading.Thread(target=run, name="explorer-warm-up", daemon=True).start()


class _AfterRest:
    """Call ``fn`` with the document locked once :meth:`poke` has not been called for ``delay_ms``.

    The timer runs on the IO loop, not as a document callback: a document callback added while the
    document is held (:meth:`Explorer._held`) can be lost when the hold is released.

    Parameters
    ----------
    doc : bokeh.document.Document
        The session's document (a served session's: without a server there is no rest to wait for).
    loop : tornado.ioloop.IOLoop
        The server's loop.
    delay_ms : int
        The rest [ms].
    fn : callable
        Called without arguments.
    """

    def __init__(self, doc: Document, loop: IOLoop, delay_ms: int, fn: Callable[[], None]) -> None:
        self.doc, self.loop, self.delay, self.fn = doc, loop, delay_ms / 1000, fn
        self.due = 0.0
        self.pending = False
        self.fired = False

    def poke(self) -> None:
        """(Re)start the rest."""
        self.due = time.monotonic() + self.delay
        if not self.pending:
            self._arm(self.delay)

    def _arm(self, wait: float) -> None:
        self.pending = True
        self.loop.call_later(wait + 0.001, self._tick)

    def _tick(self) -> None:
        self.fired = False
        try:
            self.doc.add_next_tick_callback(self._fire)
        except Exception:  # the session is gone
            self.pending = False
            return
        # a next-tick callback added while the document is held can be lost when the hold is released (then the
        # rest never ended: the link was not written after the last slider step); look again in a second
        self.loop.call_later(1.0, self._retry)

    def _retry(self) -> None:
        if self.pending and not self.fired:
            self._tick()

    def _fire(self) -> None:
        if not self.pending or self.fired:
            return  # a retried callback after the first one ran
        self.fired = True
        wait = self.due - time.monotonic()
        if wait > 0.001:  # poked again since: wait for the rest
            self._arm(wait)
            return
        self.pending = False
        self.fn()


def _batched(method: Callable[Concatenate[Explorer, _P], _R]) -> Callable[Concatenate[Explorer, _P], _R]:
    """Run an event handler of :class:`Explorer` in :meth:`Explorer._held` (its changes sent as one message)."""
    @wraps(method)
    def run(self: Explorer, *args: _P.args, **kwargs: _P.kwargs) -> _R:
        with self._held():
            return method(self, *args, **kwargs)
    return run


class Explorer:
    """One session of the explorer.

    Parameters
    ----------
    origin : Origin
        The command line's parameter space.
    query : Mapping[str, str]
        The page's URL query (a link's state).
    """

    def __init__(self, origin: Origin, query: dict[str, str]) -> None:
        import panel as pn

        self.pn = pn
        self.origin = origin
        self.count = 0
        self.doc = pn.state.curdoc
        self._loop: IOLoop | None = None
        if self.doc is not None:
            from tornado.ioloop import IOLoop

            self._loop = IOLoop.current()
        self.errors: dict[str, str] = {}
        state = origin.initial_state()
        refused = query.get(REFUSED_KEY)
        query = {k: v for k, v in query.items() if k in LINK_KEYS}
        try:
            if refused is not None:  # the server answered a link beyond the limits with this page
                raise ParameterError(link_limit_message(refused))  # (names only a key it knows)
            state = origin.complete(ViewState.from_query(query, state)) if query else state
            for key in ("along", "x", "y"):  # a name the link gives is checked, not replaced by the default
                if query.get(key) and getattr(state, key) != query[key]:
                    origin.space_of(_with_axis(state, key, query[key]))  # the one-line message naming it
                    raise ParameterError(f"'{key}' = {query[key]!r} in the link is not a settable name here")
            if query.get("t_end"):
                check_t_end(state.t_end)
            origin.space_of(state)
        except BrakesquealError as exc:
            self.errors["link"] = f"link: {exc}; showing the command line's view"
            state = origin.initial_state()
        self.state = state
        self.space = origin.space_of(state)
        self.shown: dict[str, Any] = {}
        self._map_key: _Key | None = None
        # rests timed on the server's loop (without a server the link and the texts follow at once)
        self._url_rest: _AfterRest | None = None
        self._info_rest: _AfterRest | None = None
        if self.doc is not None and self._loop is not None:
            self._url_rest = _AfterRest(self.doc, self._loop, URL_DELAY_MS, lambda: self._write_url_now())
            self._info_rest = _AfterRest(self.doc, self._loop, INFO_REST_MS,
                                         lambda: self.info_lane.submit(self.state))
        self._tracks_key: _Key | None = None
        self._tracks: ModeTracks | None = None
        self._drawn_tracks: ModeTracks | None = None
        self._cs_key: _Key | None = None
        self._hopf_key: _Key | None = None
        self._building = False
        self._sync_shown: ViewState | None = None
        self.ranges: dict[str, SliderRange] = self._preset_ranges()
        self._map_logs = (self.ranges[state.x].log, self.ranges[state.y].log)
        self._map_axes = (state.x, state.y)
        self._make_widgets()
        self._make_figures()
        self._rebuild_parameters()
        schedule = self._schedule
        # the long computations run in child processes that Cancel kills (started on first use)
        self.sim_child = ChildProcess("explorer-simulation")
        self.cycles_child = ChildProcess("explorer-cycles")
        self.region_child = ChildProcess("explorer-region")
        self._region_shown: _Key | None = None
        self._region_data: dict[str, Any] = {}
        self.locus_lane: LatestWorker[ViewState, _Locus] = LatestWorker(
            self._compute_locus, self._show_locus, schedule, name="explorer-locus")
        self.map_lane: LatestWorker[ViewState, dict[str, Any]] = LatestWorker(
            self._compute_map, self._show_map, schedule, progress=self._map_progress, name="explorer-map")
        self.info_lane: LatestWorker[ViewState, dict[str, Any]] = LatestWorker(
            self._compute_info, self._show_info, schedule, name="explorer-info")
        self.cycles_lane: LatestWorker[ViewState, CyclesView] = LatestWorker(
            self._compute_cycles, self._show_cycles, schedule, progress=self._cycles_progress,
            name="explorer-cycles")
        self.region_lane: LatestWorker[ViewState, RegionView] = LatestWorker(
            self._compute_region, self._show_region, schedule, progress=self._region_progress,
            name="explorer-region")
        self.sim_lane: LatestWorker[ViewState, SimulationView] = LatestWorker(
            self._compute_sim, self._show_sim, schedule, progress=self._sim_progress, name="explorer-sim")
        self.page = self._layout()
        self._refresh_alert()
        # The map and the texts follow the eigenvalues once the page has loaded (their work would otherwise
        # compete with building and sending the first view); without a server they follow at once.
        self._loaded = self.doc is None
        if self.doc is None or not self._first_locus():
            self._submit()
        if pn.state.curdoc is not None:
            pn.state.onload(self._on_load)

    def _first_locus(self) -> bool:
        """Put the first eigenvalues and root locus into the page itself when the server's warm-up has computed
        them (waiting at most :data:`WARM_WAIT_S`), so that the first view needs no update after the browser
        connects.  False otherwise: the locus lane computes them (it waits for the warm-up first)."""
        state, space = self.state, self.space
        key, rng = _locus_key(space, state, self.ranges)
        tracks = _WARM.tracks_for(key, timeout=WARM_WAIT_S)
        if tracks is None:
            return False
        try:  # one linearization: the model's compiled code is loaded
            lv = locus_view(space, state.along, rng, tracks=tracks)
        except BrakesquealError:
            return False
        self._tracks_key, self._tracks = key, tracks
        self._sync_shown = state
        self._show_locus(state, (space, lv, True), None)
        return True

    @_batched
    def _on_load(self) -> None:
        """The page is shown: the map and texts follow, and the simulation's views are built now rather than on
        the first press of Simulate (a running simulation holds the interpreter in long compiled stretches,
        and the event loop that builds the views and handles *Cancel* would wait for it)."""
        self._loaded = True
        self._write_url_now()
        self._follow()
        self._ensure_dynamics()

    def _follow(self) -> None:
        """The map (when its inputs changed) and the texts follow the eigenvalues (latest request only)."""
        if not self._loaded:
            return
        if self._map_key is None or self._map_key != _map_key(self.space, self.state):
            self.map_lane.submit(self.state)
        self._submit_info()

    # ------------------------------------------------------------------------------------------ plumbing
    def _schedule(self, fn: Callable[[], None]) -> None:
        """Run ``fn`` on the document's event loop with the document locked (callable from any thread)."""
        doc = self.doc
        if doc is None:  # no server (tests of the object): run now
            fn()
            return
        # Through the IO loop (thread-safe), not doc.add_next_tick_callback from the worker thread: the event
        # loop batches each interaction's changes in a hold (:meth:`_held`), and a callback that another thread
        # adds while the document is held can be dropped when the hold is released.
        loop = self._loop
        if loop is None:
            self._add_tick(doc, fn)
        else:
            loop.add_callback(self._add_tick, doc, fn)

    def _add_tick(self, doc: Document, fn: Callable[[], None]) -> None:
        try:
            doc.add_next_tick_callback(partial(self._held_call, fn))
        except Exception:  # the session is gone
            self.stop()

    def _held_call(self, fn: Callable[[], None]) -> None:
        with self._held():
            fn()

    def _held(self) -> AbstractContextManager[object]:
        """Collect the document changes of one interaction and send them to the browser in one message.

        Unheld, every changed property is a message of its own, and the browser re-lays out the page and
        repaints the plots once per message.
        """
        if self.doc is None:
            return contextlib.nullcontext()
        return self.pn.io.hold(self.doc)

    def stop(self) -> None:
        """End the session's worker threads and child processes."""
        lanes = ("locus_lane", "map_lane", "info_lane", "cycles_lane", "sim_lane", "region_lane")
        for lane in (getattr(self, n, None) for n in lanes):
            if lane is not None:
                lane.stop()
        for child in (getattr(self, n, None) for n in ("sim_child", "cycles_child", "region_child")):
            if child is not None:
                child.stop()

    def _in_child(self, child: ChildProcess, lane: LatestWorker[Any, Any], fn: Callable[..., _R],
                  args: tuple[Any, ...], check: Callable[[float], None]) -> _R:
        """``fn(*args, progress=check)`` in ``child``, killed when ``lane`` is cancelled; in this thread when
        the arguments cannot be sent to a process (then only ``check`` can stop it)."""
        try:
            return child.call(fn, args, progress=check, cancelled=lambda: lane.cancelled)
        except CannotSend:  # e.g. a model made in a notebook
            log.debug("computing in the server's thread: the arguments cannot be sent", exc_info=True)
            return fn(*args, progress=check)

    # ------------------------------------------------------------------------------------------ widgets
    def _make_widgets(self) -> None:
        pn = self.pn
        self.model_select = pn.widgets.Select(label="model", options=self.origin.models(), value=self.state.model,
                                              width=160)
        self.preset_select = pn.widgets.Select(label="preset", options=self.origin.presets(self.state.model),
                                               value=self.state.preset, width=160)
        self.model_select.param.watch(self._on_model, "value")
        self.preset_select.param.watch(self._on_preset, "value")
        self.alert = pn.pane.HTML("", visible=False, sizing_mode="stretch_width", css_classes=["bs-alert"],
                                  styles=_ALERT_STYLE)  # escaped text: never Markdown (a link's value is in it)
        self.params_box = pn.Column(sizing_mode="stretch_width")
        self.more_box = pn.Card(title="more parameters", collapsed=True, sizing_mode="stretch_width",
                                css_classes=["bs-more"])
        self.more_box.param.watch(self._on_more_card, "collapsed")
        self._more_names: list[str] = []
        self.fixed_box = pn.Card(title="fixed parameters", collapsed=True, sizing_mode="stretch_width")
        self.fixed_box.param.watch(self._on_fixed_card, "collapsed")
        self.along_select = pn.widgets.Select(label="root locus along", width=120)
        self.x_select = pn.widgets.Select(label="map x", width=95)
        self.y_select = pn.widgets.Select(label="map y", width=95)
        self.nx_input = pn.widgets.IntInput(label="x points", value=self.state.nx, start=2, width=90)
        self.ny_input = pn.widgets.IntInput(label="y points", value=self.state.ny, start=2, width=90)
        for w in (self.along_select, self.x_select, self.y_select, self.nx_input, self.ny_input):
            w.param.watch(self._on_view, "value")
        self.t_end_input = pn.widgets.FloatInput(label="simulated time [s]", value=self.state.t_end, start=0.001,
                                                 end=MAX_T_END, width=130)
        self.t_end_input.param.watch(self._on_view, "value")
        self.sim_button = pn.widgets.Button(label="Simulate", color="primary", width=100)
        self.sim_button.on_click(self._on_simulate)
        self.cycles_button = pn.widgets.Button(label="Cycles", width=80)
        self.cycles_button.on_click(self._on_cycles)
        self.region_button = pn.widgets.Button(label="Region", width=80, css_classes=["bs-region"],
                                               description="Hopf curves (blue: supercritical, red: subcritical) and "
                                                           "codimension-2 points over the map's box")
        self.region_button.on_click(self._on_region)
        self.cancel_button = pn.widgets.Button(label="Cancel", width=80)
        self.cancel_button.on_click(self._on_cancel)
        self.map_progress = pn.indicators.Progress(value=0, max=100, width=150, visible=False)
        self.sim_progress = pn.indicators.Progress(value=0, max=100, width=150, visible=False)
        self.cycles_progress = pn.indicators.Progress(value=0, max=100, width=150, visible=False,
                                                      css_classes=["bs-cycles-progress"])
        self.region_progress = pn.indicators.Progress(value=None, max=100, width=150, visible=False,
                                                      css_classes=["bs-region-progress"])
        self.leading_text = pn.pane.HTML("", sizing_mode="stretch_width")
        self.cs_text = pn.pane.HTML("critical speed: …", sizing_mode="stretch_width")
        self.hopf_text = pn.pane.HTML("Hopf: …", sizing_mode="stretch_width")
        self.map_text = pn.pane.HTML("", sizing_mode="stretch_width")
        self.sim_text = pn.pane.HTML("Press Simulate to integrate the nonlinear equations and hear the squeal.",
                                     sizing_mode="stretch_width")
        self.cycles_text = pn.pane.HTML("Press Cycles to continue the limit cycles from the Hopf point on the path.",
                                        sizing_mode="stretch_width")
        self.region_text = pn.pane.HTML("Press Region to draw the Hopf curves over the map (squeal regions).",
                                        sizing_mode="stretch_width")
        # export of the current view: the map's data with the library's writers, the modes along the locus's path
        # (the figures' own "save" tools write PNG files)
        self._map_view: MapView | None = None
        self.map_nc_download = pn.widgets.FileDownload(callback=partial(self._map_file, "netcdf"), filename="map.nc",
                                                       label="map (NetCDF)", width=115, disabled=True,
                                                       css_classes=["bs-export-map-nc"])
        self.map_csv_download = pn.widgets.FileDownload(callback=partial(self._map_file, "csv"), filename="map.csv",
                                                        label="map (CSV)", width=105, disabled=True,
                                                        css_classes=["bs-export-map-csv"])
        self.locus_download = pn.widgets.FileDownload(callback=self._locus_file, filename="locus.csv",
                                                      label="locus (CSV)", width=115, disabled=True,
                                                      css_classes=["bs-export-locus"])
        self.dynamics_box = pn.Column()  # the simulation's and cycles' views, built on first use
        self.fig_hist: Any = None
        self.render = pn.pane.HTML(self._render_html(), width=0, height=0, margin=0)

    def _map_file(self, fmt: str) -> io.BytesIO:
        """The shown map as a file (:func:`~.state.map_file`)."""
        if self._map_view is None:
            raise ParameterError("no map is shown yet")
        return io.BytesIO(map_file(self._map_view, fmt))

    def _locus_file(self) -> io.BytesIO:
        """The modes along the shown root locus's path as CSV (:func:`~.state.locus_file`)."""
        if self._drawn_tracks is None:
            raise ParameterError("no root locus is shown yet")
        return io.BytesIO(locus_file(self._drawn_tracks))

    def _axis_options(self) -> None:
        names = list(self.space.settable())
        self._building = True
        try:
            for w, value in ((self.along_select, self.state.along), (self.x_select, self.state.x),
                             (self.y_select, self.state.y)):
                w.options = names
                w.value = value
        finally:
            self._building = False

    def _preset_ranges(self) -> dict[str, SliderRange]:
        """Slider ranges (and so the map's extent and the path of the locus and Hopf search) of every settable name.

        Taken around the preset's own values, not the current ones: the page a link opens (its values in
        ``set``) then has the ranges of the session that made the link, so the link reproduces the view.
        """
        try:
            base = self.origin.space_of(replace(self.state, values={}))
        except ParameterError:  # the preset's own values with this view's axes: should not happen; fall back
            base = self.space
        return {n: slider_range(base, n) for n in self.space.settable()}

    def _rebuild_parameters(self) -> None:
        """One slider and one typed input per free name (the most important ones shown, the others in the
        "more parameters" card, built when it is first opened); typed inputs for the fixed names."""
        self.sliders: dict[str, Any] = {}
        self.inputs: dict[str, Any] = {}
        self.ranges = self._preset_ranges()
        shown, self._more_names = slider_names(self.space)
        self.params_box.objects = [self._slider_row(name) for name in shown]
        self.more_box.title = f"more parameters ({len(self._more_names)})"
        self.more_box.visible = bool(self._more_names)
        self.more_box.objects = []
        if not self.more_box.collapsed:
            self._build_more()
        self.fixed_box.objects = []
        if not self.fixed_box.collapsed:
            self._build_fixed()
        self._axis_options()

    def _slider_row(self, name: str) -> Viewable:
        """The slider and typed input of a free name."""
        pn = self.pn
        from bokeh.models import CustomJSTickFormatter

        space = self.space
        rng = self.ranges[name]
        value = space.value(name)
        kw: dict[str, Any] = {"format": CustomJSTickFormatter(code=_LOG_FORMAT)} if rng.log else {}
        lo, hi = rng.to_slider(rng.low), rng.to_slider(rng.high)
        slider = pn.widgets.FloatSlider(label=_label(space, name), start=lo, end=hi, step=(hi - lo) / 500,
                                        value=rng.to_slider(value), width=210, css_classes=[f"bs-slider-{name}"],
                                        **kw)
        box = pn.widgets.TextInput(value=_fmt_value(value), width=100, label=" ",
                                   css_classes=[f"bs-input-{name}"])
        slider.param.watch(lambda e, n=name: self._on_slider(n, e.new), "value")
        box.param.watch(lambda e, n=name: self._on_text(n, e.new), "value")
        _undebounce(slider, box)
        self.sliders[name], self.inputs[name] = slider, box
        return pn.Row(slider, box, sizing_mode="stretch_width")

    def _build_more(self) -> None:
        """The sliders of the less important free names (built when their card is first opened)."""
        self.more_box.objects = [self._slider_row(name) for name in self._more_names]

    @_batched
    def _on_more_card(self, event: Event) -> None:
        if not event.new and not self.more_box.objects and self._more_names:
            self._build_more()

    def _build_fixed(self) -> None:
        """Typed inputs for the fixed names (built when their card is first opened: a dozen inputs fewer to
        build and lay out before the first view)."""
        pn = self.pn
        space = self.space
        fixed = []
        for name in space.settable():
            if name in space.preset.free:
                continue
            box = pn.widgets.TextInput(label=_label(space, name), value=_fmt_value(space.value(name)), width=150,
                                       css_classes=[f"bs-input-{name}"])
            box.param.watch(lambda e, n=name: self._on_text(n, e.new), "value")
            _undebounce(box)
            self.inputs[name] = box
            fixed.append(box)
        self.fixed_box.objects = [pn.FlexBox(*fixed)]

    @_batched
    def _on_fixed_card(self, event: Event) -> None:
        if not event.new and not self.fixed_box.objects:
            self._build_fixed()

    # ------------------------------------------------------------------------------------------ figures
    def _make_figures(self) -> None:
        from bokeh.models import ColumnDataSource, LinearColorMapper
        from bokeh.models.annotations import Span
        from bokeh.plotting import figure

        pn = self.pn
        self.src_locus = ColumnDataSource(locus_lines(np.empty(0), np.empty((0, 0))))
        self.src_now = ColumnDataSource({"re": [], "im": []})
        f = figure(height=330, width=_HALF, title="root locus along the path; red: the current eigenvalues",
                   x_axis_label="Re λ [1/s]", y_axis_label="Im λ [1/s]", tools="pan,wheel_zoom,box_zoom,reset,save")
        f.line("re", "im", source=self.src_locus, line_width=1.5, color="#4c72b0", alpha=0.8)
        f.scatter("re", "im", source=self.src_now, size=9, color="#d62728", level=_MOVING)
        f.add_layout(Span(location=0, dimension="height", line_color="black", line_dash="dashed", line_width=1))
        f.css_classes = ["bs-locus"]
        self.fig_locus = f
        self.span_f = Span(location=0, dimension="height", line_color="#d62728", line_width=1, level=_MOVING)
        self.span_r = Span(location=0, dimension="height", line_color="#d62728", line_width=1, level=_MOVING)
        self.pane_locus = pn.pane.Bokeh(f, css_classes=['bs-locus'])
        self.pane_modes = pn.pane.Bokeh(self._modes_figure(False))
        self.src_map = ColumnDataSource({"image": [], "x": [], "y": [], "dw": [], "dh": []})
        self.src_boundary = ColumnDataSource({"x": [], "y": []}, name="bs-boundary")
        self.src_point = ColumnDataSource({"x": [], "y": []})
        self.src_hopf = ColumnDataSource({"xs": [], "ys": [], "color": []}, name="bs-hopf")
        self.src_special = ColumnDataSource({"x": [], "y": [], "type": []}, name="bs-special")
        self.src_folds = ColumnDataSource({"xs": [], "ys": []}, name="bs-folds")
        self.src_contact = ColumnDataSource({"x": [], "y": []}, name="bs-contact")
        self.map_mapper = LinearColorMapper(palette=_MAP_PALETTE, low=-0.5, high=3.5)
        self.pane_map = pn.pane.Bokeh(self._map_figure(*self._map_logs), css_classes=['bs-map'])

    def _ensure_dynamics(self) -> None:
        """Build the views of the simulation and the limit cycles (time history, spectrum, audio, branches).

        Built once the page has loaded (or on the first press of Simulate or Cycles, if earlier) rather than
        with the page: four empty views fewer to build, send and lay out before the first eigenvalues show.
        """
        if self.fig_hist is not None:
            return
        from bokeh.models import ColumnDataSource
        from bokeh.models.annotations import Span, Title
        from bokeh.plotting import figure

        pn = self.pn
        self.src_hist = ColumnDataSource({"t": [], "x": []})
        self.src_spec = ColumnDataSource({"f": [], "a": []})
        h = figure(height=220, width=480, title="time history", x_axis_label="t [s]", y_axis_label="deviation",
                   tools="pan,wheel_zoom,box_zoom,reset,save")
        h.line("t", "x", source=self.src_hist, line_width=0.8)
        self.fig_hist = h
        s = figure(height=220, width=340, title="spectrum", x_axis_label="frequency [Hz]",
                   y_axis_label="amplitude", y_axis_type="log", tools="pan,wheel_zoom,box_zoom,reset,save")
        s.line("f", "a", source=self.src_spec, line_width=0.8)
        self.fig_spec = s
        self.src_cycles = ColumnDataSource({"p": [], "a": [], "color": []})
        self.span_loss = Span(location=None, dimension="height", line_color="#d62728", line_dash="dotted",
                              line_width=2)
        c = figure(height=220, width=420,
                   title="limit cycles (blue: stable, red: unstable, grey: beyond the contact loss)",
                   x_axis_label="path parameter", y_axis_label="tilt amplitude [rad]",
                   tools="pan,wheel_zoom,box_zoom,reset,save")
        c.scatter("p", "a", source=self.src_cycles, color="color", size=5)
        c.add_layout(self.span_loss)
        if isinstance(c.title, Title):  # figure() made it one
            c.title.text_font_size = "9pt"
        self.fig_cycles = c
        self.audio = pn.pane.Audio(None, name="squeal", sample_rate=AUDIO_RATE, width=320,
                                   css_classes=["bs-audio"])
        self.dynamics_box.objects = [pn.Row(self.fig_hist, self.fig_spec), pn.Row(self.audio, self.fig_cycles)]

    def _modes_figure(self, log: bool) -> Column:
        from bokeh.layouts import column
        from bokeh.plotting import figure

        xt: Literal["log", "linear"] = "log" if log else "linear"
        name = self.state.along
        lab = _label(self.space, name)
        a = figure(height=165, width=_HALF, title="mode coupling", x_axis_type=xt, y_axis_label="f [Hz]",
                   tools="pan,wheel_zoom,box_zoom,reset,save")
        a.line("value", "freq", source=self.src_locus, line_width=1.5, color="#4c72b0")
        a.add_layout(self.span_f)
        b = figure(height=165, width=_HALF, x_axis_type=xt, x_axis_label=lab, y_axis_label="Re λ [1/s]",
                   x_range=a.x_range, tools="pan,wheel_zoom,box_zoom,reset,save")
        b.line("value", "re", source=self.src_locus, line_width=1.5, color="#4c72b0")
        b.add_layout(self.span_r)
        return column(a, b)

    def _map_figure(self, x_log: bool, y_log: bool) -> Figure:
        from bokeh.events import Tap
        from bokeh.models import CustomJSTickFormatter
        from bokeh.models.annotations import Title
        from bokeh.plotting import figure

        st = self.state
        f = figure(height=380, width=450, title="stability map (blue cross: the current point; click to move there)",
                   x_axis_label=_label(self.space, st.x) + (" (log)" if x_log else ""),
                   y_axis_label=_label(self.space, st.y) + (" (log)" if y_log else ""),
                   tools="tap,pan,wheel_zoom,box_zoom,reset,save")
        # color_mapper: a property of the Image glyph that bokeh's typed image() keywords leave out
        f.image("image", x="x", y="y", dw="dw", dh="dh", source=self.src_map,
                color_mapper=self.map_mapper)  # type: ignore[call-arg]
        f.line("x", "y", source=self.src_boundary, line_color="black", line_width=2, legend_label="boundary")
        f.multi_line("xs", "ys", source=self.src_hopf, line_color="color", line_width=3)
        f.multi_line("xs", "ys", source=self.src_folds, line_color=_FOLD_COLOUR, line_width=2, line_dash="dashed")
        f.scatter("x", "y", source=self.src_contact, marker="x", size=9, line_width=2, color=_FOLD_COLOUR)
        f.scatter("x", "y", source=self.src_special, marker="diamond", size=13, color="black")
        f.text("x", "y", text="type", source=self.src_special, x_offset=7, y_offset=-4, text_font_size="9pt")
        f.scatter("x", "y", source=self.src_point, marker="cross", size=16, line_width=3, color=_POINT,
                  level=_MOVING)
        f.legend.location = "bottom_right"
        if isinstance(f.title, Title):  # figure() made it one
            f.title.text_font_size = "9pt"
        if x_log:
            f.xaxis.formatter = CustomJSTickFormatter(code=_LOG_FORMAT)
        if y_log:
            f.yaxis.formatter = CustomJSTickFormatter(code=_LOG_FORMAT)
        f.css_classes = ["bs-map"]
        f.on_event(Tap, self._on_tap)
        self.fig_map = f
        self._map_logs = (x_log, y_log)
        return f

    def _layout(self) -> Viewable:
        pn = self.pn
        head = pn.Row(pn.pane.HTML("<h2 style='margin:4px 0'>brakesqueal explorer</h2>"), self.model_select,
                      self.preset_select, sizing_mode="stretch_width")
        left = pn.Column(self.params_box, self.more_box, self.fixed_box,
                         pn.Row(self.along_select, self.x_select, self.y_select),
                         pn.Row(self.nx_input, self.ny_input, self.map_progress),
                         pn.Row(self.t_end_input, self.sim_button),
                         pn.Row(self.cycles_button, self.region_button, self.cancel_button),
                         pn.Row(self.cycles_progress, self.region_progress),
                         self.sim_progress,
                         width=_LEFT)
        legend = pn.pane.HTML(f"<small>map: <span style='background:{MAP_STABLE}'>&nbsp;stable&nbsp;</span> "
                              f"<span style='background:{MAP_UNSTABLE}'>&nbsp;unstable&nbsp;</span> "
                              "<span style='background:#c8c8c8'>&nbsp;no verdict&nbsp;</span> "
                              f"<span style='background:{MAP_PAD_ONLY}'>&nbsp;disk stable, only a pad's own 0 Hz "
                              "mode unstable&nbsp;</span>; black: the exact "
                              "boundary (refined by bisection); blue cross: the current point; after Region: Hopf "
                              "curves (blue supercritical, red subcritical, grey undecided), codimension-2 points "
                              "(black diamonds), fold-of-cycles curves (dashed purple) and where cycles lose "
                              "contact before they fold (purple crosses)</small>")
        export = pn.Row(self.map_nc_download, self.map_csv_download, self.locus_download)
        texts = pn.Column(self.leading_text, self.cs_text, self.hopf_text, self.map_text, legend, export, self.sim_text,
                          self.cycles_text, self.region_text, width=_TEXTS)
        views = pn.Column(pn.Row(self.pane_locus, self.pane_modes), pn.Row(self.pane_map, texts),
                          self.dynamics_box)
        return pn.Column(head, self.alert, pn.Row(left, views), self.render, sizing_mode="stretch_width")

    # ------------------------------------------------------------------------------------------ state changes
    def _refresh_alert(self) -> None:
        text = "; ".join(self.errors.values())
        self.alert.object = html.escape(text)
        self.alert.visible = bool(text)

    def _set_state(self, state: ViewState, *, source: str) -> bool:
        """Validate and adopt a new state (False, with the message shown, if it is refused)."""
        try:
            space = self.origin.space_of(state)
        except BrakesquealError as exc:
            self.errors[source] = str(exc)
            self._refresh_alert()
            return False
        self.errors.pop(source, None)
        self.errors.pop("link", None)
        self._refresh_alert()
        self.state, self.space = state, space
        self._write_url()
        self._submit()
        return True

    def _write_url(self) -> None:
        """Write the state to the URL once it has rested for :data:`URL_DELAY_MS` (one history entry per pause,
        not one per slider step: Panel's location pushes a browser-history entry per change)."""
        if self._url_rest is None:  # no server
            self._write_url_now()
            return
        self._url_rest.poke()

    def _write_url_now(self) -> None:
        """Write the state as the page's query, replacing it (the token and other parameters go)."""
        from urllib.parse import urlencode

        loc = self.pn.state.location
        if loc is not None:
            try:
                loc.search = "?" + urlencode(self.state.to_query())
            except Exception:  # no browser location (tests of the object)
                log.debug("no location", exc_info=True)

    @_batched
    def _on_slider(self, name: str, position: float) -> None:
        if self._building:
            return
        value = self.ranges[name].from_slider(position)
        text = _fmt_value(value)
        self._building = True
        try:
            self.inputs[name].value = text
        finally:
            self._building = False
        self._set_state(self.state.with_values({name: text}), source=name)

    @_batched
    def _on_text(self, name: str, text: str) -> None:
        if self._building:
            return
        if self._set_state(self.state.with_values({name: text.strip()}), source=name) and name in self.sliders:
            rng = self.ranges[name]
            self._building = True
            try:
                self.sliders[name].value = rng.to_slider(self.space.value(name))
            finally:
                self._building = False

    def _move_to(self, changes: dict[str, float]) -> None:
        """Set several values (a click on the map), updating their widgets."""
        texts = {n: _fmt_value(v) for n, v in changes.items()}
        if not self._set_state(self.state.with_values(texts), source="map click"):
            return
        self._building = True
        try:
            for n, t in texts.items():
                if n in self.inputs:
                    self.inputs[n].value = t
                if n in self.sliders:
                    self.sliders[n].value = self.ranges[n].to_slider(float(t) if t != "inf" else math.inf)
        finally:
            self._building = False

    @_batched
    def _on_tap(self, event: BokehEvent) -> None:
        from bokeh.events import Tap

        if not isinstance(event, Tap) or event.x is None or event.y is None:  # (registered for Tap events)
            return
        x_log, y_log = self._map_logs
        x = 10.0 ** event.x if x_log else float(event.x)
        y = 10.0 ** event.y if y_log else float(event.y)
        self._move_to({self.state.x: x, self.state.y: y})

    @_batched
    def _on_view(self, event: Event) -> None:
        if self._building:
            return
        st = self.state
        new = replace(st, along=self.along_select.value, x=self.x_select.value, y=self.y_select.value,
                      nx=int(self.nx_input.value or 0), ny=int(self.ny_input.value or 0),
                      t_end=float(self.t_end_input.value or 0))
        self._set_state(new, source="view")

    def _reset_to(self, state: ViewState, source: str) -> None:
        try:
            state = self.origin.complete(state)
        except BrakesquealError as exc:
            self.errors[source] = str(exc)
            self._refresh_alert()
            return
        if self._set_state(state, source=source):
            self._building = True
            try:
                self.preset_select.options = self.origin.presets(state.model)
                self.preset_select.value = state.preset
            finally:
                self._building = False
            self._rebuild_parameters()

    @_batched
    def _on_model(self, event: Event) -> None:
        if self._building:
            return
        self._reset_to(ViewState(model=event.new, preset="", nx=self.state.nx, ny=self.state.ny,
                                 t_end=self.state.t_end), "model")

    @_batched
    def _on_preset(self, event: Event) -> None:
        if self._building or not event.new:
            return
        self._reset_to(ViewState(model=self.state.model, preset=event.new, nx=self.state.nx, ny=self.state.ny,
                                 t_end=self.state.t_end), "preset")

    @_batched
    def _on_simulate(self, event: Event) -> None:
        self._ensure_dynamics()
        self.sim_text.object = "simulating …"
        self.sim_progress.value, self.sim_progress.visible = 0, True
        self.sim_lane.submit(self.state)

    @_batched
    def _on_cycles(self, event: Event) -> None:
        self._ensure_dynamics()
        self.cycles_text.object = "continuing the limit cycles … (Cancel stops it)"
        self.cycles_progress.value, self.cycles_progress.visible = 0, True
        self.cycles_lane.submit(self.state)

    def _compute_cycles(self, state: ViewState, check: Callable[[float], None]) -> CyclesView:
        space = self.origin.space_of(state)
        rng = self.ranges.get(state.along) or slider_range(space, state.along)
        return self._in_child(self.cycles_child, self.cycles_lane, cycles_view, (space, state.along, rng), check)

    def _cycles_progress(self, fraction: float) -> None:
        self.cycles_progress.value = _percent(fraction)

    def _show_cycles(self, state: ViewState, cv: CyclesView | None, error: BaseException | None) -> None:
        self.cycles_progress.visible = False
        if error is not None or cv is None:  # (a delivered view comes with no error)
            self._show_failure("cycles", self.cycles_text, "limit cycles", state, error)
        else:
            self._ensure_dynamics()
            lifted = np.zeros(cv.p.size, dtype=bool)
            if cv.contact_loss is not None and cv.p.size:  # the branch starts at the Hopf point
                lifted = np.abs(cv.p - cv.p[0]) > abs(cv.contact_loss - cv.p[0])
            judged = cv.judged if cv.judged is not None else np.ones(cv.p.size, dtype=bool)
            self.src_cycles.data = {"p": cv.p, "a": cv.amplitude,
                                    "color": ["#bbbbbb" if off or not ok else _CYCLE_STABLE if st else _CYCLE_UNSTABLE
                                              for st, off, ok in zip(cv.stable, lifted, judged)]}
            self.span_loss.location = cv.contact_loss
            self.fig_cycles.xaxis.axis_label = _label(self.origin.space_of(state), state.along)
            self.cycles_text.object = html.escape(cv.summary)
            self.shown["cycles"] = {"state": state.to_query(), "points": int(cv.p.size),
                                    "contact_loss": cv.contact_loss, "summary": cv.summary}
        self._mark()

    @_batched
    def _on_region(self, event: Event) -> None:
        self.region_text.object = "continuing the Hopf curves over the map's box … (Cancel stops it)"
        self.region_progress.visible = True
        self.region_lane.submit(self.state)

    def _compute_region(self, state: ViewState, check: Callable[[float], None]) -> RegionView:
        space = self.origin.space_of(state)
        rx, ry = (self.ranges.get(n) or slider_range(space, n) for n in (state.x, state.y))
        return self._in_child(self.region_child, self.region_lane, region_view, (space, state.x, state.y, rx, ry),
                              check)

    def _region_progress(self, fraction: float) -> None:
        self.region_progress.visible = fraction < 1.0
        self.region_progress.value = _percent(fraction) if fraction > 0 else None

    def _clear_region(self) -> None:
        self.src_hopf.data = {"xs": [], "ys": [], "color": []}
        self.src_special.data = {"x": [], "y": [], "type": []}
        self.src_folds.data = {"xs": [], "ys": []}
        self.src_contact.data = {"x": [], "y": []}
        self._region_shown = None

    def _show_region(self, state: ViewState, rv: RegionView | None, error: BaseException | None) -> None:
        self.region_progress.visible = False
        if error is not None or rv is None:  # (a delivered view comes with no error)
            self._show_failure("region", self.region_text, "squeal region", state, error)
            self._mark()
            return
        x_log, y_log = self._map_logs

        def tx(v: np.ndarray) -> np.ndarray:
            return np.log10(v) if x_log else v

        def ty(v: np.ndarray) -> np.ndarray:
            return np.log10(v) if y_log else v

        xs, ys, colours = [], [], []
        for cx, cy, crit in rv.hopf:
            for rx_, ry_, c in _criticality_runs(cx, cy, crit):
                xs.append(tx(rx_))
                ys.append(ty(ry_))
                colours.append(_HOPF_COLOURS.get(c, _HOPF_UNDECIDED))
        self.src_hopf.data = {"xs": xs, "ys": ys, "color": colours}
        self.src_special.data = {"x": [float(tx(np.array(s[1]))) for s in rv.special],
                                 "y": [float(ty(np.array(s[2]))) for s in rv.special],
                                 "type": [s[0] for s in rv.special]}
        self.src_folds.data = {"xs": [tx(fx) for fx, _ in rv.folds], "ys": [ty(fy) for _, fy in rv.folds]}
        self.src_contact.data = {"x": tx(rv.contact[0]), "y": ty(rv.contact[1])}
        self._region_shown = _region_key(self.origin.space_of(state), state)
        self._region_data = rv.data
        self.region_text.object = f"<b>squeal region:</b> {html.escape(rv.summary)}"
        self.shown["region"] = {"state": state.to_query(), "curves": len(rv.hopf), "pieces": len(xs),
                                "special_points": [s[0] for s in rv.special], "fold_curves": len(rv.folds),
                                "contact_loss_points": int(rv.contact[0].size),
                                "summary": rv.summary}
        self._mark()

    @_batched
    def _on_cancel(self, event: Event) -> None:
        self.region_lane.cancel()
        self.cycles_lane.cancel()
        self.sim_lane.cancel()
        self.map_lane.cancel()
        self.info_lane.cancel()

    def _submit(self) -> None:
        """The eigenvalues first; the map lane follows each delivered locus (so it never delays the first view).

        When the root locus is kept (only the path parameter moved) and the lane is idle, the current
        eigenvalues (one linearization, well under a millisecond) are computed and shown at once, without
        the round trip through the lane's thread.
        """
        state = self.state
        lane = self.locus_lane
        if self.doc is not None and not lane.busy and not lane.superseded:
            try:
                result = self._reused_locus(state)
            except BrakesquealError:
                result = None  # the lane reports the error
            if result is not None:
                self._sync_shown = state
                self._show_locus(state, result, None)
                return
        self._sync_shown = None
        lane.submit(state)

    def _submit_info(self) -> None:
        """Compute the critical speeds and the Hopf point once the state has rested for :data:`INFO_REST_MS`.

        Critical speeds take about 10 ms of the interpreter per point; computed on every step of a moving
        slider they would hold up the event loop that sends the next root locus.
        """
        if self._info_rest is None:  # no server
            self.info_lane.submit(self.state)
            return
        self._info_rest.poke()

    def _reused_locus(self, state: ViewState) -> _Locus | None:
        """The locus of ``state`` if its path is the one kept, else None."""
        space = self.space if state is self.state else self.origin.space_of(state)
        key, rng = _locus_key(space, state, self.ranges)
        tracks = self._tracks
        if tracks is None or key != self._tracks_key:
            return None
        return space, locus_view(space, state.along, rng, tracks=tracks), True

    # ------------------------------------------------------------------------------------------ lanes
    def _compute_locus(self, state: ViewState, check: Callable[[float], None]) -> _Locus:
        """The current eigenvalues, then the modes along the path (reused while only ``along`` itself moves)."""
        space = self.origin.space_of(state)
        key, rng = _locus_key(space, state, self.ranges)
        if key == self._tracks_key:
            return space, locus_view(space, state.along, rng, tracks=self._tracks), True
        warmed = _WARM.tracks_for(key)  # the server's warm-up may be computing this very path
        if warmed is not None:
            self._tracks_key, self._tracks = key, warmed
            return space, locus_view(space, state.along, rng, tracks=warmed), True
        now = locus_view(space, state.along, rng, path=False)
        self._schedule(partial(self._show_locus, state, (space, now, False), None))  # the eigenvalues at once
        if self.locus_lane.superseded:  # a newer value waits: its path, not this one, is worth computing
            return space, now, False
        lv = locus_view(space, state.along, rng)
        if lv.tracks is not None:
            self._tracks_key, self._tracks = key, lv.tracks
        return space, lv, True

    def _mark(self) -> None:
        self.count += 1
        self.render.object = self._render_html()

    def _render_html(self) -> str:
        data = json.dumps(self.shown, default=str)
        return (f"<div id='bs-render' data-count='{self.count}' data-shown='{html.escape(data, quote=True)}' "
                "style='display:none'></div>")

    def _show_locus(self, state: ViewState, result: _Locus | None, error: BaseException | None) -> None:
        if self._sync_shown is self.state and state is not self.state:
            return  # a lane's result for an older state, after the current one was shown at once
        self._follow()
        if error is not None or result is None:  # (a delivered result comes with no error)
            self.leading_text.object = f"<b>leading eigenvalue:</b> {html.escape(str(error))}"
            self.shown["locus"] = {"state": state.to_query(), "error": str(error)}
            self._mark()
            return
        space, lv, complete = result
        lead = format_eigenvalue(lv.leading)
        verdict = "unstable (squeal)" if lv.leading.real > 0 else "stable"
        self.leading_text.object = (f"<b>leading eigenvalue</b> λ = <span id='bs-leading'>{lead}</span> 1/s "
                                    f"({abs(lv.leading.imag) / (2 * math.pi):.6g} Hz) — {verdict}")
        upper = lv.eigenvalues[lv.eigenvalues.imag >= 0]
        self.src_now.data = {"re": upper.real.tolist(), "im": upper.imag.tolist()}
        current = space.value(state.along)
        self.span_f.location = self.span_r.location = current if math.isfinite(current) else None
        tr = lv.tracks
        if tr is not None and tr is not self._drawn_tracks:  # unchanged paths are not sent again
            self._drawn_tracks = tr
            self.src_locus.data = locus_lines(tr.values, tr.eigenvalues)  # float64 arrays: binary buffers
            self.locus_download.filename = f"locus_{state.along}.csv"
            self.locus_download.disabled = False
            log_now = bool(tr.log)
            if getattr(self, "_modes_key", None) != (state.along, log_now, state.model, state.preset):
                self._modes_key = (state.along, log_now, state.model, state.preset)
                self.pane_modes.object = self._modes_figure(log_now)
        if lv.message:  # no path: clear the previous one rather than show it for another point
            self._drawn_tracks = None
            self.locus_download.disabled = True
            self.src_locus.data = locus_lines(np.empty(0), np.empty((0, 0)))
            self.leading_text.object += f"<br><i>{html.escape(lv.message)}</i>"
        x, y = self._map_point(space, state)
        self.src_point.data = {"x": [x], "y": [y]}
        previous = self.shown.get("locus", {}).get("tracks_state")
        self.shown["locus"] = {"state": state.to_query(), "leading": lead, "re": lv.leading.real,
                               "im": lv.leading.imag, "point": [x, y],
                               "tracks_state": state.to_query() if complete else previous}
        self._mark()

    def _map_point(self, space: ParameterSpace, state: ViewState) -> tuple[float, float]:
        x_log, y_log = self._map_logs
        vx, vy = space.value(state.x), space.value(state.y)
        rx, ry = self.ranges.get(state.x), self.ranges.get(state.y)
        if rx is not None and math.isinf(vx):
            vx = rx.high
        if ry is not None and math.isinf(vy):
            vy = ry.high
        return (math.log10(vx) if x_log and vx > 0 else vx), (math.log10(vy) if y_log and vy > 0 else vy)

    def _compute_map(self, state: ViewState, check: Callable[[float], None]) -> dict[str, Any]:
        space = self.origin.space_of(state)
        ranges = {n: (self.ranges.get(n) or slider_range(space, n)) for n in (state.x, state.y)}
        out: dict[str, Any] = {}
        map_key = _map_key(space, state)
        if map_key != self._map_key:
            try:
                out["map"] = map_view(space, state.x, state.y, ranges[state.x], ranges[state.y], state.nx, state.ny,
                                      progress=check)
                self._map_key = map_key
            except BrakesquealError as exc:
                out["map_error"] = str(exc)
                self._map_key = None
        return out

    def _compute_info(self, state: ViewState, check: Callable[[float], None]) -> dict[str, Any]:
        """Critical speeds and the Hopf point nearest the current value (each recomputed when its inputs change)."""
        space = self.origin.space_of(state)
        rng = self.ranges.get(state.along) or slider_range(space, state.along)
        out: dict[str, Any] = {}
        defs = {k: str(v) for k, v in space.definitions().items()}
        cs_key = (state.model, state.preset, tuple(sorted(defs.items())))
        if cs_key != self._cs_key:
            out["cs"] = critical_speed_text(space)
            self._cs_key = cs_key
        check(0.5)
        hopf_key = (state.model, state.preset, state.along,
                    tuple(sorted((k, v) for k, v in defs.items() if k != state.along)))
        if hopf_key != self._hopf_key:
            self._hopf_points = hopf_scan(space, state.along, rng)
            self._hopf_key = hopf_key
        out["hopf"] = hopf_text(self._hopf_points, state.along, space.value(state.along), rng)
        return out

    def _show_info(self, state: ViewState, out: dict[str, Any] | None, error: BaseException | None) -> None:
        if error is not None or out is None:  # (a delivered result comes with no error)
            self._cs_key = self._hopf_key = None
            self.hopf_text.object = f"<b>Hopf:</b> {html.escape(str(error))}"
        else:  # an unchanged text is not sent again
            if "cs" in out and self.cs_text.object != (cs := html.escape(out["cs"])):
                self.cs_text.object = cs
            if "cs" in out:
                self.shown["cs"] = out["cs"]
            if self.hopf_text.object != (hopf := html.escape(out["hopf"])):
                self.hopf_text.object = hopf
            self.shown["hopf"] = out["hopf"]
        self.shown["info_state"] = state.to_query()
        self._mark()

    def _map_progress(self, fraction: float) -> None:
        self.map_progress.visible = fraction < 1.0
        self.map_progress.value = int(100 * fraction)

    def _show_map(self, state: ViewState, out: dict[str, Any] | None, error: BaseException | None) -> None:
        self.map_progress.visible = False
        if error is not None or out is None:  # (a delivered result comes with no error)
            self._map_key = None
            if not isinstance(error, Cancelled):
                self.map_text.object = f"<b>map:</b> {html.escape(str(error))}"
            else:
                self.map_text.object = "<b>map:</b> cancelled"
            self._mark()
            return
        if "map_error" in out:
            self.map_text.object = f"<b>map:</b> {html.escape(out['map_error'])}"
            self.shown["map"] = {"state": state.to_query(), "error": out["map_error"]}
        if "map" in out:
            mv: MapView = out["map"]
            self._draw_map(state, mv)
        elif "map_error" not in out:
            return  # the map did not change: nothing to send
        self._mark()

    def _draw_map(self, state: ViewState, mv: MapView) -> None:
        tx = np.log10(mv.x) if mv.x_log else mv.x
        ty = np.log10(mv.y) if mv.y_log else mv.y
        code = np.where(mv.status <= 1, mv.stable.astype(np.int8), 2).astype(np.float32)
        pad_only = mv.pad_only if mv.pad_only.shape == code.shape else np.zeros(code.shape, dtype=bool)
        code[pad_only] = 3  # disk modes stable, only a massless pad's own 0 Hz mode unstable
        dx = (tx[-1] - tx[0]) / max(tx.size - 1, 1)
        dy = (ty[-1] - ty[0]) / max(ty.size - 1, 1)
        if self._map_logs != (mv.x_log, mv.y_log) or getattr(self, "_map_axes", None) != (state.x, state.y):
            self._map_axes = (state.x, state.y)
            self.pane_map.object = self._map_figure(mv.x_log, mv.y_log)
        if self._region_shown is not None and self._region_shown != _region_key(self.origin.space_of(state), state):
            self._clear_region()  # drawn for other axes or parameters
        self.src_map.data = {"image": [code], "x": [tx[0] - dx / 2], "y": [ty[0] - dy / 2],
                             "dw": [tx[-1] - tx[0] + dx], "dh": [ty[-1] - ty[0] + dy]}
        bx = np.log10(mv.boundary_x) if mv.x_log else mv.boundary_x
        by = np.log10(mv.boundary_y) if mv.y_log else mv.boundary_y
        # the refined boundary is that of every mode: left out where the colours show the disk's modes
        self.src_boundary.data = {"x": bx[:0], "y": by[:0]} if pad_only.any() else {"x": bx, "y": by}
        self._map_view = mv
        for w, suffix in ((self.map_nc_download, "nc"), (self.map_csv_download, "csv")):
            w.filename = f"map_{state.x}_{state.y}.{suffix}"
            w.disabled = False
        space = self.origin.space_of(state)
        px, py = self._map_point(space, state)
        self.src_point.data = {"x": [px], "y": [py]}
        n = mv.x.size * mv.y.size
        frac = float(np.mean(mv.stable))
        self.map_text.object = (f"<b>map:</b> {mv.x.size} × {mv.y.size} = {n:,} points (at most {MAX_MAP_POINTS:,}), "
                                f"{100 * frac:.1f} % stable"
                                + (f" ({int(pad_only.sum()):,} more with stable disk modes: only a massless pad's own "
                                   "0 Hz mode is unstable there)" if pad_only.any() else "")
                                + f", boundary with {int(np.isfinite(mv.boundary_x).sum())} "
                                f"refined vertices; {html.escape(mv.method)}")
        self.shown["map"] = {"state": state.to_query(), "points": n, "stable_fraction": frac,
                             "pad_only": int(pad_only.sum()),
                             "boundary_vertices": int(np.isfinite(mv.boundary_x).sum())}

    def _compute_sim(self, state: ViewState, check: Callable[[float], None]) -> SimulationView:
        return self._in_child(self.sim_child, self.sim_lane, simulation_view,
                              (self.origin.space_of(state), state.t_end), check)

    def _sim_progress(self, fraction: float) -> None:
        self.sim_progress.value = _percent(fraction)

    def _show_failure(self, key: str, text: Any, title: str, state: ViewState, error: BaseException | None) -> None:
        """Show a lane's error (or its cancellation) in its ``text`` pane and record it as ``shown[key]``."""
        msg = "cancelled" if isinstance(error, Cancelled) else str(error)
        text.object = f"<b>{title}:</b> {html.escape(msg)}"
        self.shown[key] = {"state": state.to_query(), "error": msg}

    def _show_sim(self, state: ViewState, sv: SimulationView | None, error: BaseException | None) -> None:
        self.sim_progress.visible = False
        if error is not None or sv is None:  # (a delivered view comes with no error)
            self._show_failure("sim", self.sim_text, "simulation", state, error)
            self._mark()
            return
        self._ensure_dynamics()
        self.src_hist.data = {"t": sv.t, "x": sv.x}
        self.fig_hist.yaxis.axis_label = sv.coordinate
        keep = sv.f > 0
        self.src_spec.data = {"f": sv.f[keep], "a": np.maximum(sv.spectrum[keep], 1e-300)}
        self.audio.object = sv.audio
        self.sim_text.object = html.escape(sv.summary) + f" — audio {sv.duration:.3f} s"
        self.shown["sim"] = {"state": state.to_query(), "duration": sv.duration, "samples": int(sv.audio.size),
                             "summary": sv.summary}
        self._mark()


def build_page(origin: Origin) -> Viewable:
    """The page of one session (Panel calls this once per browser tab).

    Parameters
    ----------
    origin : Origin
        The command line's parameter space.

    Returns
    -------
    panel.viewable.Viewable
    """
    import panel as pn

    args = pn.state.session_args or {}
    query = {k: (v[0].decode("utf-8", "replace") if isinstance(v[0], bytes) else str(v[0]))
             for k, v in args.items() if v}
    ex = Explorer(origin, query)
    pn.state.on_session_destroyed(lambda ctx: ex.stop())
    return ex.page


def check(state: ViewState, origin: Origin) -> None:
    """Raise ParameterError unless ``state`` resolves (used by the command before serving)."""
    try:
        origin.space_of(state)
    except BrakesquealError as exc:
        raise ParameterError(str(exc)) from None
