"""Starting and stopping one SITL autopilot: ArduPlane (lock-stepped, fresh parameters at
every start) or PX4 with its SIH fixed wing (on the wall clock, sped up).

Both listen on 127.0.0.1 only (ArduPlane through the build's loopback shim, PX4 as built).
Each instance runs in its own temporary directory, removed when it stops."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..autopilot.navigation import CALM, Wind
from ..errors import LinkError


@dataclass(frozen=True)
class SitlSettings:
    """What one flight's autopilot is started with.

    ``parameters``: name -> value laid over the stock defaults (ArduPlane: the build's
    ``plane.parm``; PX4: the SIH airframe's).  ``heading_deg``: where the aircraft stands
    facing at home (degrees true; ArduPlane only -- PX4's SIH starts facing north).
    ``speedup``: simulated seconds per wall second (ArduPlane is lock-stepped, its flight
    does not depend on it; PX4's SIH is not, keep it modest).  ``instance`` moves the ports."""

    latitude_deg: float
    longitude_deg: float
    altitude_amsl_m: float
    heading_deg: float = 0.0
    parameters: dict[str, float] = field(default_factory=dict)
    wind: Wind = CALM
    speedup: float = 20.0
    instance: int = 0


class ArduPlaneSitl:
    """``with ArduPlaneSitl(folder, settings) as sitl:`` -- ``sitl.connection`` is its first
    serial port (MAVLink 2 over TCP on loopback)."""

    autopilot = "ardupilot"

    def __init__(self, folder: Path, settings: SitlSettings) -> None:
        self.folder, self.settings = Path(folder), settings
        self.port = 5760 + 10 * settings.instance
        self.connection = f"tcp:127.0.0.1:{self.port}"
        self._run: Path | None = None
        self._process: subprocess.Popen | None = None

    def __enter__(self) -> "ArduPlaneSitl":
        s = self.settings
        self._run = Path(tempfile.mkdtemp(prefix="dtsp-arduplane-"))
        extra = dict(s.parameters)
        # SITL's wind: speed, the direction it comes from (degrees true), no turbulence
        extra.update(SIM_WIND_SPD=s.wind.speed_m_s, SIM_WIND_DIR=s.wind.from_deg % 360.0,
                     SIM_WIND_TURB=0.0)
        (self._run / "extra.parm").write_text("".join(f"{k} {v:g}\n" for k, v in extra.items()))
        env = dict(os.environ, LD_PRELOAD=str(self.folder / "libloopback.so"))
        command = [str(self.folder / "arduplane"), "--model", "plane", "--speedup", f"{s.speedup:g}",
                   "--home", f"{s.latitude_deg:.8f},{s.longitude_deg:.8f},"
                             f"{s.altitude_amsl_m:.2f},{s.heading_deg % 360.0:.1f}",
                   "--defaults", f"{self.folder / 'plane.parm'},{self._run / 'extra.parm'}",
                   f"-I{s.instance}", "-w"]
        self._process = subprocess.Popen(command, cwd=self._run, env=env, stdin=subprocess.DEVNULL,
                                         stdout=open(self._run / "sitl.log", "wb"),
                                         stderr=subprocess.STDOUT, start_new_session=True)
        _wait_for_port(self.port, self._process, self._run / "sitl.log", 20.0)
        return self

    def __exit__(self, *exc) -> None:
        _end(self._process)
        if self._run is not None:
            shutil.rmtree(self._run, ignore_errors=True)


class Px4Sitl:
    """``with Px4Sitl(folder, settings) as sitl:`` -- ``sitl.connection`` is the ground
    station's UDP port PX4 sends to, 14550 + the instance (bind it with udpin).

    Started as the build's ``start.sh`` starts it (a fresh run directory with PX4's start-up
    scripts, ``PX4_PARAM_*`` applied after the airframe's defaults), but done here: the
    build's ``px4-*`` command links may have been copied as plain files (then every ``param``
    command of the start-up fails and no airframe is loaded), so they are made again as links
    to the ``px4`` binary."""

    autopilot = "px4"
    AIRFRAME = "10041"            # sihsim_airplane

    def __init__(self, folder: Path, settings: SitlSettings) -> None:
        self.folder, self.settings = Path(folder), settings
        self.connection = f"udpin:127.0.0.1:{14550 + settings.instance}"
        self._run: Path | None = None
        self._process: subprocess.Popen | None = None

    def __enter__(self) -> "Px4Sitl":
        s = self.settings
        if s.wind.speed_m_s > 0:
            raise LinkError("PX4's SIH (v1.16) has no wind: fly PX4 in calm air")
        run = self._run = Path(tempfile.mkdtemp(prefix="dtsp-px4-"))
        shutil.copytree(self.folder / "etc", run / "etc")
        for path in (run / "etc").rglob("*"):
            path.chmod(path.stat().st_mode | 0o200)
        (run / "bin").mkdir()
        binary = self.folder / "bin" / "px4"
        (run / "bin" / "px4").symlink_to(binary)
        for command in (self.folder / "bin").glob("px4-*"):
            if command.name.endswith(".sh"):
                shutil.copy(command, run / "bin" / command.name)
            else:
                (run / "bin" / command.name).symlink_to(binary)
        links = run / "etc" / "init.d-posix" / "px4-rc.mavlink"
        text = links.read_text()
        ground = "mavlink start -x -u $udp_gcs_port_local -r 4000000 -f"
        if ground not in text:
            raise LinkError(f"PX4 SITL: {links.name} is not the one this driver knows")
        # the ground station's port follows the instance (PX4 sends to 14550 for every one)
        links.write_text(text.replace(ground, ground + " -o $((14550+px4_instance))", 1))
        simulator = run / "etc" / "init.d-posix" / "px4-rc.simulator"
        text = simulator.read_text()
        anchor = 'if [ "$PX4_SIMULATOR" = "sihsim" ]'
        if anchor not in text:
            raise LinkError(f"PX4 SITL: {simulator.name} is not the one this driver knows")
        apply = ('env | while IFS="=" read -r line; do name=${line%%=*}; case $name in '
                 'PX4_PARAM_*) param set "${name#PX4_PARAM_}" "${line#*=}" ;; esac; done\n\n')
        simulator.write_text(text.replace(anchor, apply + anchor, 1))
        env = dict(os.environ, PX4_HOME_LAT=f"{s.latitude_deg:.8f}",
                   PX4_HOME_LON=f"{s.longitude_deg:.8f}", PX4_HOME_ALT=f"{s.altitude_amsl_m:.2f}",
                   PX4_SIM_SPEED_FACTOR=f"{s.speedup:g}", PX4_SYS_AUTOSTART=self.AIRFRAME,
                   PX4_SIMULATOR="sihsim", PX4_SIM_MODEL="sihsim_airplane",
                   PATH=f"{run / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")
        for name, value in s.parameters.items():
            env[f"PX4_PARAM_{name}"] = f"{value:g}"
        self._process = subprocess.Popen(
            [str(run / "bin" / "px4"), "-d", "-i", str(s.instance), "-w", str(run), str(run)],
            cwd=run, env=env, stdin=subprocess.DEVNULL, stdout=open(run / "px4.log", "wb"),
            stderr=subprocess.STDOUT, start_new_session=True)
        time.sleep(0.5)
        if self._process.poll() is not None:
            raise LinkError("PX4 SITL ended at start: "
                            + (run / "px4.log").read_text(errors="replace")[-500:])
        return self

    def log_tail(self) -> str:
        """The end of PX4's console output (for an error message)."""
        if self._run is None or not (self._run / "px4.log").exists():
            return ""
        return (self._run / "px4.log").read_text(errors="replace")[-400:]

    def __exit__(self, *exc) -> None:
        _end(self._process)
        if self._run is not None:
            shutil.rmtree(self._run, ignore_errors=True)


def _wait_for_port(port: int, process: subprocess.Popen, log: Path, timeout_s: float) -> None:
    """Until the SITL says it waits for its first client on ``port``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        text = log.read_text(errors="replace")
        if process.poll() is not None:
            raise LinkError(f"ArduPlane SITL ended at start: {text[-500:]}")
        if f"SERIAL0 on TCP port {port}" in text and "Waiting for connection" in text:
            return
        time.sleep(0.05)
    _end(process)
    raise LinkError(f"ArduPlane SITL did not listen on port {port} within {timeout_s:g} s")


def _end(process: subprocess.Popen | None) -> None:
    if process is None or process.poll() is not None:
        return
    try:
        os.killpg(process.pid, signal.SIGTERM)
        process.wait(timeout=5)
    except (ProcessLookupError, subprocess.TimeoutExpired):
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait(timeout=5)
