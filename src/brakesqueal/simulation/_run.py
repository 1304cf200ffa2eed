r"""One integration of :func:`~._integrate.simulate`: the compiled DOP853 in calls of bounded wall time, or SciPy's
``solve_ivp``; the estimation record and the pads' contact states."""

from __future__ import annotations

import math
import time
from typing import Any, Callable, Literal, Sequence

import numpy as np

from ..model.options import stick_slip_everywhere
from ..status import RunStatus
from ._model import SilentState, SimulationModel
from .trajectory import EstimationRecord

__all__ = ["CHUNK_SECONDS", "EstimationGrid", "Run", "engagement_at"]

#: Wall time [s] of one call of the compiled integrator (between calls progress is reported, Ctrl-C acts and
#: other threads get the interpreter lock: the explorer's server stays responsive while a simulation runs).
CHUNK_SECONDS = 0.02


def engagement_at(t: np.ndarray, engaged0: np.ndarray, switch_times: Sequence[Sequence[float]]) -> np.ndarray:
    """Contact state of every pad at the times ``t`` from its initial state and its switching times.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Times (increasing).
    engaged0 : ndarray of bool, shape (n_pads,)
        Whether each pad is pressed at the start.
    switch_times : sequence of sequences
        Per pad, its lift-off and re-contact times in increasing order.

    Returns
    -------
    ndarray of bool, shape (N, n_pads)
        A pad switched at time ``t_s`` has its new state from ``t > t_s`` on.
    """
    out = np.empty((t.size, engaged0.size), dtype=bool)
    for j in range(engaged0.size):
        flips = np.searchsorted(np.asarray(switch_times[j], dtype=float), t)  # switches at times < t
        out[:, j] = engaged0[j] ^ (flips % 2 == 1)
    return out


class EstimationGrid:
    """The estimation record being filled: times ``t0 + i dt`` in a ring buffer of ``size`` rows."""

    def __init__(self, t0: float, dt: float, size: int, width: int) -> None:
        self.t0, self.dt = float(t0), float(dt)
        self.buf = np.full((size, width), np.nan)
        self.count = 0  # samples written so far (index of the next one)

    def put(self, Y: np.ndarray) -> None:
        """Append samples (rows of ``Y``, at the next grid times)."""
        size, k = self.buf.shape[0], Y.shape[0]
        idx = (self.count + np.arange(k)) % size
        if k > size:
            idx, Y = idx[-size:], Y[-size:]
        self.buf[idx] = Y
        self.count += k

    def times(self, a: float, b: float) -> tuple[int, np.ndarray]:
        """Index of the first grid time ``>= a`` and the grid times in ``[a, b]``."""
        i0 = max(int(math.ceil((a - self.t0) / self.dt)) - 1, 0)
        while self.t0 + i0 * self.dt < a:
            i0 += 1
        i1 = int(math.floor((b - self.t0) / self.dt)) + 1
        while self.t0 + i1 * self.dt > b:
            i1 -= 1
        i = np.arange(i0, i1 + 1)
        return i0, self.t0 + i * self.dt

    def record(self) -> EstimationRecord:
        """The last ``min(count, size)`` samples in time order."""
        size = self.buf.shape[0]
        m = min(self.count, size)
        i = np.arange(self.count - m, self.count)
        return EstimationRecord(t=self.t0 + i * self.dt, y=self.buf[i % size].copy(), rate=1.0 / self.dt,
                                complete=self.count <= size)  # fmt: skip


class Run:
    """One integration: the compiled DOP853 in calls of bounded wall time, or SciPy's ``solve_ivp``."""

    def __init__(self, model: SimulationModel, p: np.ndarray, st: SilentState, y0: np.ndarray, l0: np.ndarray,
                 dl0: np.ndarray, f0: np.ndarray, ev0: np.ndarray, t0: float, t1: float, rtol: float,
                 atol: np.ndarray, max_step: float, t_out: np.ndarray, est: EstimationGrid, events: str,
                 progress: Callable[[float], None] | None, engaged: np.ndarray | None = None) -> None:
        self.model, self.p, self.st = model, p, st
        self.y0, self.l0, self.dl0, self.f0, self.ev0 = y0, l0, dl0, f0, ev0
        self.t0, self.t1, self.rtol, self.atol, self.max_step = t0, t1, rtol, atol, max_step
        self.t_out, self.est, self.events, self.progress = t_out, est, events, progress
        self.npad = len(model.pads)
        self.engaged = engaged
        #: every pad has regularised stick-slip (law ``stick``): ``events="stop"`` stops at contact loss only
        self.stick = stick_slip_everywhere(model.spec)

    def _event_name(self, k: int) -> tuple[str, str]:
        pad = self.model.pads[k % self.npad]
        return (("contact-loss", "sliding-reversal", "re-contact")[k // self.npad]), pad

    def _status(self, code: int, t: float, k_event: int, t_event: float | None) -> tuple[RunStatus, str]:
        if code == 0:
            return RunStatus.FINISHED, "reached the end time"
        if code == 1:
            kind, pad = self._event_name(k_event)
            if kind == "contact-loss":
                return RunStatus.CONTACT_LOSS, f"pad '{pad}' lost contact (F_n <= 0) at t = {t_event:.6g} s"
            return (RunStatus.SLIDING_REVERSAL,
                    f"sliding at pad '{pad}' reversed (v_r . v_r0 <= 0) at t = {t_event:.6g} s")
        reason = {
            -1: "step size became too small",
            -2: "the state became non-finite or the pad equations G = 0 could not be solved",
            -3: "the step budget max_steps was exhausted",
            -4: "a pad's contact switched twice within 10 minimal steps (chattering contact, e.g. a pad pressed "
                "with zero force while the disk moves along its surface)",
            -5: "an expression of the equations divided by zero (e.g. a pad's friction direction v_r/|v_r| at "
                "exactly zero sliding speed; regularised stick-slip, law 'stick', is defined there)",
        }.get(code, f"integrator error {code}")
        return RunStatus.FAILED, f"integration failed at t = {t:.6g} s: {reason}"

    def jit(self, max_steps: int) -> dict[str, Any]:
        from ._interrupt import check_interrupt

        k, est, st = self.model.kernels, self.est, self.st
        N = self.y0.size
        Y = np.full((self.t_out.size, N), np.nan)
        mode = {"off": 0, "stop": 1, "continue": 2}[self.events]
        if mode == 1 and self.stick:
            mode = 5  # a sliding reversal is ordinary motion: recorded; a contact loss stops
        eng = np.ones(self.npad, dtype=np.int64)
        if self.engaged is not None:
            mode = 4 if self.events == "stop" else 3
            eng = self.engaged.copy()
        ev_t = np.zeros(10000)
        ev_k = np.zeros(10000, dtype=np.int64)
        drained_t: list[np.ndarray] = []
        drained_k: list[np.ndarray] = []
        y, f, l, dl, ev_old = self.y0.copy(), self.f0.copy(), self.l0.copy(), self.dl0.copy(), self.ev0.copy()
        ev_prev = np.full(ev_old.size, np.inf)
        stats = np.zeros(3, dtype=np.int64)
        y_event = np.full(N, np.nan)
        h = min(1e-7, (self.t1 - self.t0) / 10)
        t, i_out, i_est, n_ev = self.t0, 0, 0, 0
        status, k_event, t_event = 0, -1, math.nan
        budget = 256
        while True:
            chunk = min(budget, max_steps - int(stats[1]))
            if chunk <= 0:
                status = -3
                break
            w0 = time.perf_counter()
            try:
                status, t, h, i_out, i_est, n_ev, k_event, t_event = k.dop853(
                    y, f, l, dl, ev_old, ev_prev, self.p, st.ztol, st.vr0, t, self.t1, h, self.rtol, self.atol,
                    self.max_step, self.t_out, i_out, Y, est.t0, est.dt, i_est, est.buf, mode, ev_t, ev_k, n_ev, chunk,
                    stats, y_event, eng)  # fmt: skip
            except ZeroDivisionError:  # numba raises for 0.0 ** -1 under any error model
                status = -5
                break
            if mode in (3, 4):  # unilateral: every switch is kept (the buffer is drained after each call)
                drained_t.append(ev_t[:n_ev].copy())
                drained_k.append(ev_k[:n_ev].copy())
                n_ev = 0
            dt = time.perf_counter() - w0
            check_interrupt()
            est.count = int(i_est)
            if self.progress is not None:
                self.progress((t - self.t0) / (self.t1 - self.t0))
            if status != 2:
                break
            budget = int(min(max(budget * CHUNK_SECONDS / max(dt, 1e-4), 16), 10_000_000))
        if mode in (3, 4):
            ev_t = np.concatenate(drained_t) if drained_t else np.zeros(0)
            ev_k = np.concatenate(drained_k) if drained_k else np.zeros(0, dtype=np.int64)
            n_ev = ev_t.size
        recorded: dict[str, list[float]] = {}
        switches: list[list[float]] = [[] for _ in range(self.npad)]
        for i in range(min(n_ev, ev_t.size)):
            kind, pad = self._event_name(int(ev_k[i]))
            recorded.setdefault(f"{kind}-pad-{pad}", []).append(float(ev_t[i]))
            if mode in (3, 4) and kind != "sliding-reversal":
                switches[int(ev_k[i]) % self.npad].append(float(ev_t[i]))
        te = float(t_event) if status == 1 else None
        st_, msg = self._status(status, t, k_event, te)
        t_final = te if te is not None else (self.t1 if status == 0 else float(t))
        return {"status": st_, "message": msg, "Y": Y, "n": i_out, "nfev": int(stats[0]), "t_event": te,
                "t_final": t_final,
                "y_event": y_event.copy() if status == 1 else None, "event_times": recorded,
                "event_pad": self._event_name(k_event)[1] if status == 1 else None, "switch_times": switches,
                "stats": {"steps": int(stats[1]), "rejected": int(stats[2])}}  # fmt: skip

    def scipy(self, method: str) -> dict[str, Any]:
        """``solve_ivp`` in chunks no longer than the estimation ring buffer (bounded memory)."""
        from scipy.integrate import solve_ivp

        from ._interrupt import check_interrupt

        k, st, est, p = self.model.kernels, self.st, self.est, self.p
        t0, t1, progress = self.t0, self.t1, self.progress
        N, npad = self.y0.size, self.npad
        lbuf, dlbuf = self.l0.copy(), self.dl0.copy()
        g, mw = np.empty(2 * lbuf.size + 1), np.empty(self.model.n ** 2 + self.model.n)
        calls = [0]

        def fun(t: float, y: np.ndarray) -> np.ndarray:
            out = np.empty(N)
            k.rhs(np.ascontiguousarray(y, dtype=float), lbuf, dlbuf, p, st.ztol, g, mw, out)
            check_interrupt()
            calls[0] += 1
            if progress is not None and calls[0] % 2000 == 0:
                progress((t - t0) / (t1 - t0))
            return out

        evfuns = []
        names = [self._event_name(i) for i in range(2 * npad)]
        if self.events != "off":
            lev, dlev = self.l0.copy(), self.dl0.copy()
            vals, cb, gev = np.empty(2 * npad), np.empty(7 * npad), np.empty(2 * lbuf.size + 1)

            def make(i: int) -> Callable[[float, np.ndarray], float]:
                def ev(t: float, y: np.ndarray) -> float:
                    yy = np.ascontiguousarray(y, dtype=float)
                    # the same start every call: an event function must be a function of y alone (SciPy's root
                    # finder re-evaluates the step's ends; a warm start from the last call can change the sign)
                    lev[:], dlev[:] = self.l0, self.dl0
                    k.solve_pads(yy, lev, dlev, p, st.ztol, gev)
                    k.event_values(yy, lev, dlev, p, st.vr0, cb, vals)
                    return float(vals[i])

                # with regularised stick-slip a sliding reversal (i >= npad) is recorded, not terminal
                ev.terminal = self.events == "stop" and not (self.stick and i >= npad)  # type: ignore[attr-defined]
                ev.direction = -1  # type: ignore[attr-defined]
                return ev

            evfuns = [make(i) for i in range(2 * npad)]
        t_out = self.t_out
        Y = np.full((t_out.size, N), np.nan)
        n = 0
        nfev = 0
        t_event, y_event, k_event = None, None, -1
        recorded: dict[str, list[float]] = {}
        chunk = est.buf.shape[0] * est.dt
        a, y = t0, np.asarray(self.y0, dtype=float)
        code, t_end, sol_msg = 0, t0, ""
        first = True
        while True:
            b = min(a + chunk, t1)
            if t1 - b < 1e-9 * chunk:
                b = t1
            lo: Literal["left", "right"] = "left" if first else "right"
            i0, i1 = int(np.searchsorted(t_out, a, side=lo)), int(np.searchsorted(t_out, b, side="right"))
            _, te = est.times(a, b)
            if not first:
                te = te[te > a]
            ts, inv = np.unique(np.concatenate([t_out[i0:i1], te, [b]]), return_inverse=True)
            try:
                sol = solve_ivp(fun, (a, b), y, method=method, t_eval=ts, rtol=self.rtol, atol=self.atol,
                                max_step=self.max_step, events=evfuns or None)  # fmt: skip
            except ZeroDivisionError:  # numba raises for 0.0 ** -1 under any error model
                code, t_end, sol_msg = -5, a, ""
                break
            nfev += int(sol.nfev)
            got = int(np.size(sol.t))  # SciPy leaves t and y as empty lists when it fails before a requested time
            Yc = np.ascontiguousarray(np.asarray(sol.y, dtype=float).T) if got else np.empty((0, N))
            io, ie = inv[: i1 - i0], inv[i1 - i0 : i1 - i0 + te.size]
            ok_o, ok_e = io < got, ie < got
            Y[i0 : i0 + int(ok_o.sum())] = Yc[io[ok_o]]
            n = i0 + int(ok_o.sum())
            est.put(Yc[ie[ok_e]])
            if evfuns:
                for i, tev in enumerate(sol.t_events):
                    if tev.size:
                        kind, pad = names[i]
                        recorded.setdefault(f"{kind}-pad-{pad}", []).extend(float(v) for v in tev)
                        if sol.status == 1 and (t_event is None or tev[0] < t_event):
                            t_event, y_event, k_event = float(tev[0]), np.asarray(sol.y_events[i][0]), i
            code = {0: 0, 1: 1, -1: -2}[sol.status]
            t_end = float(sol.t[-1]) if got else a
            sol_msg = sol.message
            if code != 0 or b >= t1:
                break
            a, y, first = b, Yc[inv[-1]].copy(), False  # ts ends at b: the state to continue from
        if progress is not None:
            progress(1.0)
        st_, msg = self._status(code, t_end, k_event, t_event)
        if code == -2:
            msg = f"solve_ivp ({method}) failed: {sol_msg}"
        t_final = t_event if code == 1 and t_event is not None else (t1 if code == 0 else t_end)
        return {"status": st_, "message": msg, "Y": Y, "n": n, "nfev": nfev, "t_event": t_event, "t_final": t_final,
                "y_event": y_event,
                "event_times": recorded if self.events == "continue" else (
                    {k_: v for k_, v in recorded.items() if k_.startswith("sliding-reversal")} if self.stick else {}),
                "event_pad": names[k_event][1] if code == 1 else None}  # fmt: skip
