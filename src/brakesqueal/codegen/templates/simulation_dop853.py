"""Template: the simulation's integrator (numba): the shared DOP853 step with dense output and events.

:func:`brakesqueal.codegen.simulation.kernel_source` appends the text below the
marker line after :mod:`.simulation_pads` and :mod:`.dop853`: the driver
``dop853`` runs the one DOP853 step (:func:`.dop853.dop853_step`, SciPy's
coefficients, error norm and step-size control) for a bounded number of steps
per call and keeps its whole state in arrays, so a run split into calls is
bitwise the same as one call.  Between steps it writes the dense output
(7th order) at the output and estimation times and locates the events
(contact loss ``F_n <= 0`` and sliding reversal ``v_r . v_r0 <= 0`` of every
pad; with unilateral contact the pads' lift-off and re-contact).

The stand-ins above the marker only make this file a valid, linted module.
"""
# ruff: noqa: E501
# mypy: ignore-errors

import math

import numpy as np
from numba import njit

_N = 2  # coordinates Q (generated)
_M = 2  # pad deformations L (generated)
_NPAD = 2  # pads (generated)
_NEV = 4  # event functions (generated)


def rhs_u(y, l, dl, p, ztol, g, mw, eng, D, out):  # template simulation_pads
    raise NotImplementedError


def solve_pads_e(y, l, dl, p, ztol, g, eng):  # template simulation_pads
    raise NotImplementedError


def event_values_u(y, l, dl, p, vr0, cb, eng, out):  # template simulation_pads
    raise NotImplementedError


def dop853_step(ctx, y, h, rtol, atol, K, ynew, ystage):  # template dop853
    raise NotImplementedError


def dop853_factor(err, rejected):  # template dop853
    raise NotImplementedError


_DA = np.zeros((16, 16))  # template dop853
_DD = np.zeros((7, 16))  # template dop853


# ---- template body ----


@njit(cache=True, error_model="numpy")
def dense_eval(F, y_old, x, out):
    """SciPy's Dop853DenseOutput at normalized time x in [0, 1] of the step from y_old."""
    n = y_old.shape[0]
    nf = F.shape[0]
    for j in range(n):
        acc = 0.0
        for k in range(nf):
            acc += F[nf - 1 - k, j]
            if k % 2 == 0:
                acc *= x
            else:
                acc *= 1.0 - x
        out[j] = acc + y_old[j]


@njit(cache=True, inline="always", error_model="numpy")
def _stage_rhs(ctx, y, out):
    """The right-hand side of the DOP853 stages: rhs_u with ctx = (l, dl, p, ztol, g, mw, eng, D)."""
    rhs_u(y, ctx[0], ctx[1], ctx[2], ctx[3], ctx[4], ctx[5], ctx[6], ctx[7], out)


@njit(cache=True, error_model="numpy")
def _event_at(k, x, F, y, l, dl, p, ztol, vr0, g, cb, ev, yint, eng):
    """Event function k at normalized time x of the step (pad unknowns solved from l, dl, updated)."""
    dense_eval(F, y, x, yint)
    solve_pads_e(yint, l, dl, p, ztol, g, eng)
    event_values_u(yint, l, dl, p, vr0, cb, eng, ev)
    return ev[k]


@njit(cache=True, error_model="numpy")
def _bisect(k, a, b, F, y, l0, dl0, p, ztol, vr0, g, cb, ev, yint, lb, dlb, eng):
    """First x in [a, b] with event k <= 0, given event k > 0 at a and <= 0 at b (60 halvings; returns the <= 0 end)."""
    lb[:] = l0
    dlb[:] = dl0
    for _ in range(60):
        c = 0.5 * (a + b)
        if _event_at(k, c, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng) > 0.0:
            a = c
        else:
            b = c
    return b


@njit(cache=True, error_model="numpy")
def _golden(k, a, b, F, y, l0, dl0, p, ztol, vr0, g, cb, ev, yint, lb, dlb, eng):
    """Minimum of event k on [a, b] (48 golden-section steps): returns (x, value); stops early at a value <= 0."""
    lb[:] = l0
    dlb[:] = dl0
    r = 0.6180339887498949
    c = b - r * (b - a)
    d = a + r * (b - a)
    fc = _event_at(k, c, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
    fd = _event_at(k, d, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
    for _ in range(48):
        if fc <= 0.0:
            return c, fc
        if fd <= 0.0:
            return d, fd
        if fc < fd:
            b = d
            d = c
            fd = fc
            c = b - r * (b - a)
            fc = _event_at(k, c, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
        else:
            a = c
            c = d
            fc = fd
            d = a + r * (b - a)
            fd = _event_at(k, d, F, y, lb, dlb, p, ztol, vr0, g, cb, ev, yint, eng)
    if fc < fd:
        return c, fc
    return d, fd


@njit(cache=True, error_model="numpy")
def dop853(y, f, l, dl, ev_old, ev_prev, p, ztol, vr0, t, t1, h_abs, rtol, atol, max_step, t_out, i_out, Y, te0, dte,
           i_est, Yest, event_mode, ev_t, ev_k, n_ev, budget, stats, y_event, eng):
    """Adaptive DOP853 from t towards t1 (the shared step, :func:`dop853_step`), at most ``budget`` accepted
    steps per call.

    Integrator state, updated in place: y (state), f (its derivative), l, dl (pad unknowns, solved at y),
    ev_old (event values at y), ev_prev (at the previous step's last inner point; inf at the start); stats
    (int64) accumulates nfev, accepted steps, rejected steps.  Events: sign changes between NSUB + 1 points
    per step are bisected; a sampled minimum within twice the second difference of zero (a grazing dip) is
    located by golden-section search and, if it is <= 0, the crossing before it is bisected.
    Dense output at t_out[i_out:] goes into Y; at te0 + i dte (i = i_est, ...) into the ring buffer Yest
    (row i % Yest.shape[0]).  event_mode: 0 = none, 1 = stop at the first event, 2 = record and continue,
    3 = unilateral contact (eng[j] = 1 pressed, 0 lifted; a contact event ends the step there and switches the
    pad: recorded as k = j for a lift-off, 2 NPAD + j for a re-contact), sliding reversals recorded, 4 = the same
    but stop at a sliding reversal, 5 = stop at the first contact loss, record sliding reversals (pads with
    regularised stick-slip, for which a reversal is ordinary motion).
    Returns (status, t, h_abs, i_out, i_est, n_ev, k_event, t_event): status 0 = reached t1,
    1 = stopped at an event (state in y_event), 2 = budget used or event buffer full (call again to continue),
    -1 = step size too small, -2 = non-finite state or pad equations unsolvable, -4 = a pad switched twice
    within 10 minimal steps (chattering contact).
    """
    n = y.shape[0]
    NSUB = 4
    K = np.zeros((16, n))
    F = np.zeros((7, n))
    ynew = np.empty(n)
    ystage = np.empty(n)
    yint = np.empty(n)
    g = np.empty(2 * _M + 1)
    mw = np.empty(_N * _N + _N)
    cb = np.empty(7 * _NPAD)
    ev_new = np.empty(_NEV)
    ev_mid = np.empty(_NEV)
    evs = np.empty((NSUB + 1, _NEV))
    Ls = np.empty((NSUB + 1, _M))
    dLs = np.empty((NSUB + 1, _M))
    lnew = l.copy()
    dlnew = dl.copy()
    lsave = l.copy()
    dlsave = dl.copy()
    lint = l.copy()
    dlint = dl.copy()
    lb = l.copy()
    dlb = dl.copy()
    Dw = np.empty(_NPAD * _N + 1)
    ctx = (lnew, dlnew, p, ztol, g, mw, eng, Dw)  # the stages' right-hand side (_stage_rhs)
    t_switch = np.full(_NPAD, -math.inf)
    slide_t = np.empty(_NPAD)
    k_event = -1
    t_event = math.nan
    steps = 0
    while t < t1:
        if steps >= budget or ((event_mode == 3 or event_mode == 4) and n_ev + 2 * _NPAD + 2 > ev_t.shape[0]):
            return (2, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        if h_abs < min_step:
            h_abs = min_step
        rejected = False
        while True:
            if h_abs < min_step:
                return (-1, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
            t_new = t + h_abs
            if t_new > t1:
                t_new = t1
            h = t_new - t
            h_abs = abs(h)
            lnew[:] = l
            dlnew[:] = dl
            for j in range(n):
                K[0, j] = f[j]
            err = dop853_step(ctx, y, h, rtol, atol, K, ynew, ystage)
            stats[0] += 12
            factor = dop853_factor(err, rejected)
            if err < 1.0:
                h_abs *= factor
                break
            if not err < math.inf and h_abs <= 1e3 * min_step:
                return (-2, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
            h_abs *= factor
            rejected = True
            stats[2] += 1
        steps += 1
        stats[1] += 1
        lsave[:] = lnew  # pad unknowns solved at ynew
        dlsave[:] = dlnew
        # dense output of this step (3 extra stages)
        need_dense = (i_out < t_out.shape[0] and t_out[i_out] <= t_new) or event_mode > 0 \
            or te0 + i_est * dte <= t_new
        if need_dense:  # 3 more stages and the coefficients of the 7th-order interpolant (SciPy's Dop853DenseOutput)
            for s in range(13, 16):
                for j in range(n):
                    acc = 0.0
                    for q in range(s):
                        acc += K[q, j] * _DA[s, q]
                    ystage[j] = y[j] + h * acc
                rhs_u(ystage, lnew, dlnew, p, ztol, g, mw, eng, Dw, K[s])
            stats[0] += 3
            for j in range(n):
                dy = ynew[j] - y[j]
                F[0, j] = dy
                F[1, j] = h * f[j] - dy
                F[2, j] = 2.0 * dy - h * (K[12, j] + f[j])
                for r in range(4):
                    acc = 0.0
                    for q in range(16):
                        acc += _DD[r, q] * K[q, j]
                    F[3 + r, j] = h * acc
        t_stop = t_new
        stop = False
        switch = -1
        if event_mode > 0:
            # event values at NSUB + 1 points of the step (dense output; the end with the saved pad unknowns)
            for k in range(_NEV):
                evs[0, k] = ev_old[k]
            Ls[0, :] = l
            dLs[0, :] = dl
            lint[:] = l
            dlint[:] = dl
            for sub in range(1, NSUB + 1):
                if sub == NSUB:
                    event_values_u(ynew, lsave, dlsave, p, vr0, cb, eng, ev_new)
                    Ls[sub, :] = lsave
                    dLs[sub, :] = dlsave
                else:
                    dense_eval(F, y, sub / NSUB, yint)
                    solve_pads_e(yint, lint, dlint, p, ztol, g, eng)
                    event_values_u(yint, lint, dlint, p, vr0, cb, eng, ev_new)
                    Ls[sub, :] = lint
                    dLs[sub, :] = dlint
                for k in range(_NEV):
                    evs[sub, k] = ev_new[k]
            first = -1
            tf = t_new
            for k in range(_NPAD):
                slide_t[k] = math.nan
            for k in range(_NEV):
                # in time order: a sign change between two points (bisected), or a sampled minimum close to zero
                # (a grazing dip: the minimum is located by golden-section search, and a crossing before it bisected)
                i = 0
                while i <= NSUB:
                    xc = -1.0
                    nxt = i + 1
                    if i >= 1 and evs[i - 1, k] > 0.0 and evs[i, k] <= 0.0:
                        xc = _bisect(k, (i - 1) / NSUB, i / NSUB, F, y, Ls[i - 1], dLs[i - 1], p, ztol, vr0, g, cb,
                                     ev_mid, yint, lb, dlb, eng)
                    elif evs[i, k] > 0.0:
                        left = evs[i - 1, k] if i >= 1 else ev_prev[k]
                        right = evs[i + 1, k] if i < NSUB else math.inf
                        if left > evs[i, k] and right >= evs[i, k]:
                            c = min(max(i, 1), NSUB - 1)
                            trig = 2.0 * abs(evs[c - 1, k] - 2.0 * evs[c, k] + evs[c + 1, k])
                            if evs[i, k] <= trig:
                                lo = max(i - 1, 0)
                                hi = min(i + 1, NSUB)
                                xm, vm = _golden(k, lo / NSUB, hi / NSUB, F, y, Ls[i], dLs[i], p, ztol, vr0, g, cb,
                                                 ev_mid, yint, lb, dlb, eng)
                                if vm <= 0.0:
                                    xc = _bisect(k, lo / NSUB, xm, F, y, Ls[lo], dLs[lo], p, ztol, vr0, g, cb,
                                                 ev_mid, yint, lb, dlb, eng)
                                    nxt = hi + 1
                    if xc >= 0.0:
                        tk = t + xc * h
                        if event_mode == 3 and k >= _NPAD:
                            slide_t[k - _NPAD] = tk  # recorded below if before a contact switch
                            break
                        if event_mode == 2 or (event_mode == 5 and k >= _NPAD):
                            if n_ev < ev_t.shape[0]:
                                ev_t[n_ev] = tk
                                ev_k[n_ev] = k
                            n_ev += 1
                        else:
                            if first < 0 or tk < tf:
                                first = k
                                tf = tk
                                dense_eval(F, y, xc, y_event)
                            break
                    i = nxt
            if (event_mode == 1 or event_mode == 5) and first >= 0:
                stop = True
                t_stop = tf
                k_event = first
                t_event = tf
            if event_mode == 3 or event_mode == 4:
                for k in range(_NPAD):
                    if slide_t[k] == slide_t[k] and slide_t[k] <= tf:
                        ev_t[n_ev] = slide_t[k]
                        ev_k[n_ev] = _NPAD + k
                        n_ev += 1
                if first >= _NPAD:  # a sliding reversal (event_mode 4): stop
                    stop = True
                    t_stop = tf
                    k_event = first
                    t_event = tf
                elif first >= 0:  # lift-off or re-contact of pad `first`: end the step there and switch
                    if tf - t_switch[first] <= 10.0 * min_step:
                        return (-4, tf, h_abs, i_out, i_est, n_ev, first, tf)
                    t_switch[first] = tf
                    switch = first
                    t_stop = tf
                    ev_t[n_ev] = tf
                    ev_k[n_ev] = first if eng[first] == 1 else 2 * _NPAD + first
                    n_ev += 1
            for k in range(_NEV):
                ev_prev[k] = evs[NSUB - 1, k]
                ev_old[k] = evs[NSUB, k]
        while i_out < t_out.shape[0] and t_out[i_out] <= t_stop:
            x = (t_out[i_out] - t) / h
            dense_eval(F, y, x, yint)
            for j in range(n):
                Y[i_out, j] = yint[j]
            i_out += 1
        nbuf = Yest.shape[0]
        while te0 + i_est * dte <= t_stop:
            x = (te0 + i_est * dte - t) / h
            dense_eval(F, y, x, yint)
            r = i_est % nbuf
            for j in range(n):
                Yest[r, j] = yint[j]
            i_est += 1
        if switch >= 0:
            # continue from the switching point in the other contact state (the step beyond it is discarded)
            t = t_stop
            eng[switch] = 1 - eng[switch]
            for j in range(n):
                y[j] = y_event[j]
            rhs_u(y, l, dl, p, ztol, g, mw, eng, Dw, f)
            stats[0] += 1
            event_values_u(y, l, dl, p, vr0, cb, eng, ev_old)
            for k in range(_NEV):
                ev_prev[k] = ev_old[k]  # no grazing test at the switching point itself
            continue
        t = t_new
        for j in range(n):
            y[j] = ynew[j]
            f[j] = K[12, j]
        l[:] = lsave
        dl[:] = dlsave
        if stop:
            return (1, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
    return (0, t, h_abs, i_out, i_est, n_ev, k_event, t_event)
