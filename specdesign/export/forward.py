"""Python controllers behind the Bladed interface: a DISCON library that forwards each call to Python.

The MPCs of :mod:`specdesign.mpc` (and any callable controller of
:func:`specdesign.simulate.simulate`) are Python objects stepped in time; they have no DISCON
export. :func:`forwarded` wraps one for OpenFAST: the library built from ``forward.c``
(:func:`~specdesign.export.library.forward_library`, one compiled library for every
controller) sends the swap array of each call over a local socket to a :class:`ForwardServer`,
which steps the controller and answers the pitch command (and the torque, if the controller
commands it). The library applies the exported library's pitch limits, pitch-rate limit and
torque law (``forward.c`` includes ``discon.c`` and reads the same parameters), so a forwarded
controller and an exported one differ only in where the pitch command is computed.

How the server feeds the controller: as the reduced-model simulator does
(:func:`specdesign.simulate.simulate`'s callable contract, one run). At the first call (status
0) ``controller.start(dt, wind, pitch, torque)`` with ``dt`` the library's call interval
(ServoDyn's ``DLL_DT``), the hub-height wind avrSWAP(27), the measured pitch avrSWAP(4) and the
measured torque avrSWAP(23) × gearbox ratio; then at every call, the first included,
``controller(t, y)`` with ``t`` = avrSWAP(2) and ``y`` (one-element arrays, SI, rotor shaft):

=================  =================================================================
``gen_speed``      avrSWAP(20) / gearbox ratio (rad/s)
``pitch``          avrSWAP(4), blade 1 (rad)
``power``          avrSWAP(15), electrical (W)
``tower_top_acc``  avrSWAP(53), fore-aft (m/s²)
``blade_root_my``  mean of avrSWAP(30-32), the blades' out-of-plane root moments (N·m):
                   the collective moment the reduced model's per-blade output stands for
=================  =================================================================

``measurement_filters=`` (of :func:`forwarded`; default none) low-passes chosen signals before
the controller reads them, at every call, as ROSCO filters its generator speed: a first- or
second-order low-pass (ROSCO's ``F_LPFType`` 1 and 2) discretised by Tustin's rule at the call
interval, started at steady state on the first sample (ROSCO's ``LPFilter`` and
``SecLPFilter``): the same sensor chain as ROSCO's, for a like-for-like comparison. They do not
cure the MPCs' riding of the pitch-rate limit in OpenFAST, a loop-gain problem (docs/openfast.md).

The swap array has no tower-top velocity or tower-base moment: a controller that reads them
fails with a KeyError naming what it does have. The controller is called at every library
call, as the simulator calls it at every step: a sampled controller (the MPCs' ``ts``) samples
itself and holds its command between samples, so ``ts`` must be a whole multiple of ``dt``
(checked by :func:`forwarded`). The swap array is float32: the controller reads measurements
rounded to float32 and its command is rounded to float32 on the way back, as for the exported
library.
"""
from __future__ import annotations

import copy
import math
import os
import shutil
import socket
import struct
import tempfile
import threading
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import positive_scalar
from ..controller.lti import is_lti_like
from ..controller.scheduled import ScheduledController
from ..controller.torque import TorqueLaw, rosco_lpf1, rosco_lpf2
from ..turbine import TurbineModel
from .bladed import discon_parameters
from .library import forward_library
from .parameters import DisconParameters, write_parameters

__all__ = ["FORWARD_FORMAT", "FORWARD_RECORDS", "MEASUREMENT_NAMES", "Forwarded", "ForwardServer", "ForwardError",
           "forwarded", "swap_measurements"]

#: First words of a forwarding parameter file (format name and version).
FORWARD_FORMAT = ("specdesign-forward", 1)
#: Swap records each call sends (avrSWAP(1..165): R_v43, every record ServoDyn v5.0.0 fills).
FORWARD_RECORDS = 165
#: First word of every request and reply ("SDFW" in little-endian bytes).
_MAGIC = 0x57464453
#: Longest socket path (AF_UNIX's sun_path of 108 bytes, its NUL included).
_MAX_SOCKET = 107
#: Characters of a Python traceback's tail sent back to the library (its message buffer is 1024).
_TAIL = 700
#: The measurements a forwarded controller reads (:func:`swap_measurements`), in its order.
MEASUREMENT_NAMES = ("gen_speed", "pitch", "power", "tower_top_acc", "blade_root_my")


class ForwardError(RuntimeError):
    """The Python side of a forwarded run failed; the message carries the traceback's tail."""


@dataclass(frozen=True)
class Forwarded:
    """A Python controller for the forwarding library: the controller and what the library applies.

    Made by :func:`forwarded`. ``parameters`` are the exported library's parameters with a zero
    pitch bank: the pitch limits, rate limit, torque law and gearbox ratio the library applies
    around the Python controller's command.

    Parameters
    ----------
    controller : callable
        ``controller(t, y)`` → pitch (rad), or (pitch, rotor torque N·m); optional ``start``.
    parameters : DisconParameters
        The library's parameters (``dt`` the call interval, s).
    timeout : float
        Seconds either side waits for the other (connect, each reply, each request).
    name : str
        Label.
    measurement_filters : tuple, default ()
        ``(signal, corner rad/s, damping or None)`` per low-passed measurement (second order
        with a damping, first order without), applied by the server before the controller
        reads it (:func:`forwarded`).
    """

    controller: object
    parameters: DisconParameters
    timeout: float
    name: str
    measurement_filters: tuple = ()

    @property
    def dt(self) -> float:
        """The call interval (s): ServoDyn's ``DLL_DT``."""
        return self.parameters.dt

    @property
    def library(self) -> Path:
        """The compiled forwarding library (built on first use)."""
        return forward_library()

    def text(self, socket_path: str | os.PathLike) -> str:
        """The forwarding parameter file for a server listening at ``socket_path``.

        Parameters
        ----------
        socket_path : str or os.PathLike
            The server's socket (at most 107 bytes, no blanks or ``#``).

        Returns
        -------
        str
            The file's text: the forwarding header, then the exported library's parameters.

        Raises
        ------
        ValueError
            For a socket path too long or holding blanks or ``#``.
        """
        path = os.fsdecode(socket_path)
        if len(path.encode()) > _MAX_SOCKET or not path or any(c.isspace() or c == "#" for c in path):
            raise ValueError(f"socket_path={path!r} must be 1-{_MAX_SOCKET} bytes without blanks or '#' (AF_UNIX): "
                             "put it in a short folder such as tempfile.mkdtemp()")
        with tempfile.TemporaryDirectory() as tmp:
            body = write_parameters(self.parameters, Path(tmp) / "p", comment=f"forwarded: {self.name}").read_text()
        # the measurement filters run in Python: comment lines for the reader (and in the file's digest)
        filt = "".join(f"# measurement filter (Python side): {k} low-pass {w!r} rad/s, "
                       f"{'first order' if z is None else f'second order, damping {z!r}'}\n"
                       for k, w, z in self.measurement_filters)
        head = (f"{FORWARD_FORMAT[0]} {FORWARD_FORMAT[1]}\n"
                "# specdesign.export.forwarded: each DISCON call goes to the Python server at this socket\n"
                f"{filt}socket {path}\ntimeout {self.timeout!r}\n")
        return head + body

    def write(self, path: str | os.PathLike, socket_path: str | os.PathLike) -> Path:
        """Write the forwarding parameter file (ServoDyn's ``DLL_InFile``).

        Parameters
        ----------
        path : str or os.PathLike
            The file (overwritten).
        socket_path : str or os.PathLike
            The server's socket (see :meth:`text`).

        Returns
        -------
        pathlib.Path
            ``path``.
        """
        path = Path(path)
        path.write_text(self.text(socket_path))
        return path


def forwarded(controller: object, *, dt: float = 0.02, model: TurbineModel | None = None,
              torque: str | TorqueLaw | None = None, pitch_rate_limit: float = math.inf, gearbox_ratio: float = 1.0,
              timeout: float = 60.0, name: str | None = None, measurement_filters=None) -> Forwarded:
    """A Python controller made runnable through the forwarding DISCON library.

    Parameters
    ----------
    controller : callable
        A controller of the simulator's callable contract (``controller(t, y)``, optional
        ``start(dt, wind, pitch, torque)``): :class:`specdesign.mpc.QuadraticMPC`,
        :class:`~specdesign.mpc.EconomicMPC`, :class:`~specdesign.mpc.HealthMPC`,
        :class:`~specdesign.mpc.ClonedController`, ... Each server steps its own deep copy.
    dt : float, optional
        The library's call interval (s), ServoDyn's ``DLL_DT`` (a whole multiple of OpenFAST's
        step); a sampled controller's ``ts`` must be a whole multiple of it.
    model : TurbineModel, optional
        The turbine (default :func:`specdesign.turbine.iea15mw`): pitch limits, torque law.
    torque : {"constant", "power", "rosco", "rosco_power"}, TorqueLaw or None, optional
        The library's generator-torque law, as :func:`~specdesign.export.export_discon`'s
        (default the model's ROSCO law); used when the controller returns a pitch only.
    pitch_rate_limit : float, optional
        Largest rate of the pitch command (rad/s) the library applies; default inf.
    gearbox_ratio : float, optional
        Generator / rotor speed (-).
    timeout : float, optional
        Seconds (default 60) the library waits to connect and for each reply, and the server
        for each request: a stuck side fails the run instead of hanging it.
    name : str, optional
        Label (default the controller's ``name``, else its ``__name__``, else its type's name).
    measurement_filters : mapping, optional
        Signal name (of :data:`MEASUREMENT_NAMES`) → low-pass the server applies to it at every
        call before the controller reads it: a corner frequency (rad/s, first order) or
        ``(corner rad/s, damping)`` (second order): ROSCO's ``F_LPFType`` 1 and 2, stepped as the
        simulator's ROSCO steps them (:func:`~specdesign.controller.torque.rosco_lpf1`,
        ``rosco_lpf2``). E.g. ``{"gen_speed": (1.0081, 0.7)}``
        is the IEA 15 MW deck's ROSCO speed filter. Default None: the signals as OpenFAST
        measures them.

    Returns
    -------
    Forwarded
        Give it to :func:`specdesign.validate.run_campaign` with ``plant=deck`` beside exported
        controllers, or run it yourself with :class:`ForwardServer`.

    Raises
    ------
    TypeError
        For a controller that is not callable, or an LTI or scheduled controller (export those
        with :func:`~specdesign.export.export_discon`: they run in C).
    ValueError
        For a non-positive ``dt``, ``timeout`` or ``pitch_rate_limit``, or a controller whose
        sample time ``ts`` is not a whole multiple of ``dt``; a measurement filter on an unknown
        signal, with a corner not in (0, π/dt) rad/s or a non-positive damping; the checks of
        :func:`~specdesign.export.discon_parameters`.

    Examples
    --------
    >>> from specdesign.mpc import QuadraticMPC
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> fwd = forwarded(QuadraticMPC(m, ts=0.2), dt=0.02, model=m)  # doctest: +SKIP
    >>> fwd.dt  # doctest: +SKIP
    0.02
    """
    # python-control loads matplotlib and scipy.signal at import (LOCAL_IMPORTS): only here, for the zero bank
    import control

    if is_lti_like(controller) or isinstance(controller, ScheduledController):
        raise TypeError(f"controller is a {type(controller).__name__}, which runs in C: export it with "
                        "specdesign.export.export_discon instead of forwarding it")
    if not callable(controller):
        raise TypeError(f"controller must be callable as controller(t, y) (the simulator's contract), got "
                        f"{type(controller).__name__}")
    dt = positive_scalar(dt, "dt")
    timeout = positive_scalar(timeout, "timeout")
    ts = getattr(controller, "ts", None)
    if ts is not None:
        k = float(ts) / dt
        if round(k) < 1 or abs(k - round(k)) > 1e-9 * k:
            raise ValueError(f"the controller's sample time ts = {ts} s is not a whole multiple of dt = {dt} s: give "
                             "dt = ts or a whole fraction of it")
    label = str(name if name is not None else
                getattr(controller, "name", getattr(controller, "__name__", type(controller).__name__)))
    filters = _filter_specs(measurement_filters, dt)
    p = discon_parameters(control.tf([0.0], [1.0]), dt=dt, model=model, torque=torque,
                          pitch_rate_limit=pitch_rate_limit, gearbox_ratio=gearbox_ratio, name=label)
    return Forwarded(controller=controller, parameters=p, timeout=timeout, name=label, measurement_filters=filters)


def _filter_specs(filters, dt: float) -> tuple:
    """``forwarded``'s ``measurement_filters`` checked: ((signal, corner rad/s, damping or None), ...)."""
    if filters is None:
        return ()
    if not hasattr(filters, "items"):
        raise TypeError(f"measurement_filters must be a mapping signal -> corner (rad/s) or (corner, damping), got "
                        f"{type(filters).__name__}")
    out = []
    for key, spec in filters.items():
        if key not in MEASUREMENT_NAMES:
            raise ValueError(f"measurement_filters: {key!r} is not a forwarded measurement; give one of "
                             f"{MEASUREMENT_NAMES}")
        corner, damping = (spec, None) if np.ndim(spec) == 0 else tuple(spec) if len(spec) == 2 else (None, None)
        if corner is None:
            raise ValueError(f"measurement_filters[{key!r}] = {spec!r}: give a corner (rad/s, first order) or "
                             "(corner rad/s, damping) (second order)")
        corner = positive_scalar(corner, f"measurement_filters[{key!r}] corner (rad/s)")
        if corner >= math.pi / dt:
            raise ValueError(f"measurement_filters[{key!r}]: corner {corner} rad/s is not below the Nyquist frequency "
                             f"pi/dt = {math.pi / dt:.4g} rad/s of the call interval")
        if damping is not None:
            damping = positive_scalar(damping, f"measurement_filters[{key!r}] damping")
        out.append((str(key), corner, damping))
    return tuple(out)


class _LowPass:
    """One measurement's filter: ROSCO's ``LPFilter`` (``damping`` None) or ``SecLPFilter``, the
    simulator's own steps (:func:`~specdesign.controller.torque.rosco_lpf1`, ``rosco_lpf2``:
    Tustin without prewarping, started at the first sample as ROSCO starts its filters)."""

    def __init__(self, corner: float, damping: float | None, dt: float):
        self.corner, self.damping, self.dt = corner, damping, dt
        self.state = np.zeros(4)  # last outputs and inputs
        self.first = True

    def __call__(self, x: float) -> float:
        first, self.first = self.first, False
        if self.damping is None:
            return float(rosco_lpf1(self.state, 0, 1, x, self.corner, self.dt, first))
        return float(rosco_lpf2(self.state, 0, 1, 2, 3, x, self.corner, self.damping, self.dt, first))


class _Measurements(dict):
    """The swap array's signals; a missing one names those there are."""

    def __missing__(self, key):
        raise KeyError(f"{key!r} is not in the Bladed swap array a forwarded controller reads; it has "
                       f"{sorted(self)} (measure those: e.g. tower_top_acc, not tower_top_vel)")


def swap_measurements(swap: np.ndarray, gearbox_ratio: float = 1.0) -> dict:
    """The measurements ``y`` a forwarded controller gets from one call's swap array.

    Parameters
    ----------
    swap : numpy.ndarray
        avrSWAP (float32, 0-based: record k at index k − 1), at least 53 records.
    gearbox_ratio : float, optional
        Generator / rotor speed (-).

    Returns
    -------
    dict
        Name → (1,) float64 array (SI, rotor shaft): ``gen_speed`` (rad/s), ``pitch`` (rad),
        ``power`` (W), ``tower_top_acc`` (m/s²), ``blade_root_my`` (N·m, the three blades'
        mean); see the module docstring.
    """
    sw = np.asarray(swap)
    return _Measurements(gen_speed=np.array([float(sw[19]) / gearbox_ratio]), pitch=np.array([float(sw[3])]),
                         power=np.array([float(sw[14])]), tower_top_acc=np.array([float(sw[52])]),
                         blade_root_my=np.array([(float(sw[29]) + float(sw[30]) + float(sw[31])) / 3.0]))


class ForwardServer:
    """The Python end of one forwarded run: a socket, a thread, a copy of the controller.

    Listens at ``socket_path`` (default ``<new temporary folder>/s``) from :meth:`start` (or
    entering the ``with`` block) and serves the library's connection call by call, until its
    final call (status −1) or its end, then waits for another (a ServoDyn that loads the
    library twice connects twice; each status 0 starts the controller afresh). It stops on an
    error, which is kept in :attr:`error` and sent to the library (its call then fails with the
    traceback's tail). :meth:`close` stops it and removes the socket.

    Parameters
    ----------
    forward : Forwarded
        The controller and the library's settings (:func:`forwarded`).
    socket_path : str or os.PathLike, optional
        Where to listen (at most 107 bytes); default a new temporary folder's ``s``.
    record : bool, default False
        Keep every call's ``(t, y, pitch, torque)`` in :attr:`records` (``y`` as the controller
        read it, after the measurement filters; the command as the controller returned it,
        before the library's limits; torque NaN when the library's law gives it).

    Attributes
    ----------
    error : str or None
        The Python traceback (or the malformed request) that stopped the server.
    link_error : str or None
        A broken or timed-out connection that stopped it (the library's process ended or
        stalled: its own error says why; not raised by :meth:`raise_error`).
    finished : bool
        Whether the library's final call arrived.
    calls : int
        Calls answered.
    call_times : list of float
        Wall time (s) the server spent in each call, from the request read to the reply sent.
    call_cpu_times : list of float
        CPU time (s) of the server's thread in each call, the same span (the controller's cost
        per control step, whatever else the machine runs).
    records : list
        With ``record=True``.
    started : tuple or None
        The arguments ``(dt, wind, pitch, torque)`` the controller's ``start`` was given.
    """

    def __init__(self, forward: Forwarded, socket_path: str | os.PathLike | None = None, *, record: bool = False):
        if not isinstance(forward, Forwarded):
            raise TypeError(f"forward must be a specdesign.export.Forwarded (forwarded(controller)), got "
                            f"{type(forward).__name__}")
        self.forward = forward
        self._tmp = None
        if socket_path is None:
            self._tmp = tempfile.mkdtemp(prefix="sdfw")
            socket_path = os.path.join(self._tmp, "s")
        self.socket = Path(socket_path)
        forward.text(self.socket)  # the path's checks, before anything listens
        self.record = bool(record)
        self.controller = copy.deepcopy(forward.controller)
        self.error, self.link_error, self.finished, self.calls = None, None, False, 0
        self.call_times, self.call_cpu_times, self.records, self.started = [], [], [], None
        self._filters = {}
        self._stop = threading.Event()
        self._thread = None
        self._listener = None
        self._conn = None

    def write(self, path: str | os.PathLike) -> Path:
        """Write the library's parameter file for this server (:meth:`Forwarded.write`).

        Parameters
        ----------
        path : str or os.PathLike
            The file.

        Returns
        -------
        pathlib.Path
            ``path``.
        """
        return self.forward.write(path, self.socket)

    def start(self) -> ForwardServer:
        """Listen and serve in a daemon thread.

        Returns
        -------
        ForwardServer
            ``self``.

        Raises
        ------
        OSError
            If the socket cannot be bound (an existing file there is not replaced).
        """
        if self._thread is not None:
            raise RuntimeError("ForwardServer.start: already started (one server serves one run)")
        self._listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._listener.bind(str(self.socket))
        self._listener.listen(1)
        # accept polls, so that close() stops a server no library ever connected to
        self._listener.settimeout(0.2)
        self._thread = threading.Thread(target=self._serve, name=f"ForwardServer {self.socket}", daemon=True)
        self._thread.start()
        return self

    def close(self, wait: float | None = None) -> None:
        """Stop serving and remove the socket (and its temporary folder).

        Parameters
        ----------
        wait : float, optional
            Seconds to wait for the thread (default the forward's ``timeout``).
        """
        self._stop.set()
        conn = self._conn
        if conn is not None:  # wakes a thread waiting for a request that will not come
            try:
                conn.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        if self._thread is not None:
            self._thread.join(self.forward.timeout if wait is None else wait)
        if self._listener is not None:
            self._listener.close()
            self._listener = None
        if self.socket.exists():
            self.socket.unlink()
        if self._tmp is not None:
            shutil.rmtree(self._tmp, ignore_errors=True)
            self._tmp = None

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()

    def raise_error(self, context: str = "") -> None:
        """Raise :class:`ForwardError` with the traceback's tail if the server stopped on an error.

        Parameters
        ----------
        context : str, optional
            Prefixed to the message (e.g. the case and seed).

        Raises
        ------
        ForwardError
            If :attr:`error` is set.
        """
        if self.error is not None:
            raise ForwardError(f"{context}the Python controller {self.forward.name!r} failed (its traceback's end):\n"
                               f"{self.error[-2000:]}")

    # ------------------------------------------------------------------ the thread
    def _accept(self):
        while not self._stop.is_set():
            try:
                conn, _ = self._listener.accept()
                return conn
            except TimeoutError:
                continue
            except OSError:
                return None
        return None

    def _serve(self) -> None:
        # connection after connection until close() or an error: a ServoDyn that loads the
        # library twice (its LOAD_DLL_TWICE_FOR_LOGGING_CHANNELS build: status 0, −1, then the
        # run) connects twice, and each status 0 starts the controller afresh
        while self.error is None and self.link_error is None:
            conn = self._conn = self._accept()
            if conn is None:
                return
            try:
                conn.settimeout(self.forward.timeout)
                self._connection(conn)
            except OSError as e:  # a timeout (TimeoutError) or a broken connection, unless close() cut it
                if not self._stop.is_set():
                    self.link_error = f"the connection with the library failed: {type(e).__name__}: {e}"
            finally:
                conn.close()

    def _connection(self, conn: socket.socket) -> None:
        """Answer one connection's calls until its final call, its end or an error."""
        while True:
            head = _recv(conn, 8)
            if head is None:  # the library went (OpenFAST ended or was stopped)
                return
            magic, n = struct.unpack("=II", head)
            if magic != _MAGIC or not 60 <= n <= 100000:
                self.error = f"malformed request (magic 0x{magic:08x}, {n} records): not the forwarding library"
                _reply(conn, 1, self.error.encode())
                return
            body = _recv(conn, 4 * n)
            if body is None:
                self.link_error = "the library closed the connection inside a request"
                return
            tic, tic_cpu = time.perf_counter(), time.thread_time()
            sw = np.frombuffer(body, dtype=np.float32)
            status = int(round(float(sw[0])))
            if status == -1:
                self.finished = True
                _reply(conn, 0, struct.pack("=dd", math.nan, math.nan))
                return
            try:
                pitch, torque = self._step(status, sw)
            except Exception:  # any error of the controller goes back to the library and to the caller
                self.error = traceback.format_exc()
                _reply(conn, 1, self.error[-_TAIL:].encode(errors="replace"))
                return
            _reply(conn, 0, struct.pack("=dd", pitch, torque))
            self.calls += 1
            self.call_times.append(time.perf_counter() - tic)
            self.call_cpu_times.append(time.thread_time() - tic_cpu)

    def call_statistics(self) -> dict:
        """The calls answered and their cost per call.

        Returns
        -------
        dict
            ``calls`` (int) and, once there is one, ``cpu_mean_s``, ``cpu_median_s``,
            ``cpu_p99_s``, ``cpu_max_s`` of :attr:`call_cpu_times` and the same ``wall_*`` of
            :attr:`call_times` (s); ``{"calls": 0}`` before any call.
        """
        out = {"calls": self.calls}
        for key, times in (("cpu", self.call_cpu_times), ("wall", self.call_times)):
            if times:
                t = np.asarray(times)
                out |= {f"{key}_mean_s": float(t.mean()), f"{key}_median_s": float(np.median(t)),
                        f"{key}_p99_s": float(np.percentile(t, 99)), f"{key}_max_s": float(t.max())}
        return out

    def _step(self, status: int, sw: np.ndarray) -> tuple[float, float]:
        """One call: the controller started (status 0) and stepped; (pitch rad, rotor torque N·m or NaN)."""
        p = self.forward.parameters
        gear = p.gearbox_ratio
        if status == 0:
            self.started = (p.dt, np.array([float(sw[26])]), np.array([float(sw[3])]), np.array([float(sw[22]) * gear]))
            start = getattr(self.controller, "start", None)
            if callable(start):
                start(p.dt, *(a.copy() for a in self.started[1:]))
            # fresh filters: each connection's run starts them at its own first sample
            self._filters = {k: _LowPass(w, z, p.dt) for k, w, z in self.forward.measurement_filters}
        elif status != 1:
            raise ValueError(f"avrSWAP(1) = {float(sw[0])!r}: a status of 0, 1 or -1 is expected")
        t = float(sw[1])
        y = swap_measurements(sw, gear)
        for k, f in self._filters.items():
            y[k] = np.array([f(float(y[k][0]))])
        out = self.controller(t, y)
        pitch, torque = out if isinstance(out, tuple) else (out, math.nan)
        pitch = np.asarray(pitch, dtype=float).reshape(-1)
        torque = np.asarray(torque, dtype=float).reshape(-1)
        if pitch.size != 1 or torque.size != 1:
            raise ValueError(f"the controller returned {pitch.size} pitch and {torque.size} torque values at t = {t} s, "
                             "one each expected (one run)")
        if not np.isfinite(pitch[0]) or np.isinf(torque[0]):
            raise ValueError(f"the controller returned pitch {pitch[0]!r} rad, torque {torque[0]!r} N·m at t = {t} s "
                             f"(measurements {dict(y)})")
        if self.record:
            self.records.append((t, {k: float(v[0]) for k, v in y.items()}, float(pitch[0]), float(torque[0])))
        return float(pitch[0]), float(torque[0])


def _recv(conn: socket.socket, n: int) -> bytes | None:
    """Exactly ``n`` bytes, or None if the peer closed first."""
    buf = bytearray()
    while len(buf) < n:
        chunk = conn.recv(n - len(buf))
        if not chunk:
            return None
        buf += chunk
    return bytes(buf)


def _reply(conn: socket.socket, code: int, body: bytes) -> None:
    conn.sendall(struct.pack("=IiI", _MAGIC, code, len(body)) + body)
