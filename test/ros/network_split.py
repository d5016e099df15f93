"""The robot/laptop split of the paper's TIAGo set-up, on one machine: two network namespaces.

Perception runs in the ``robot`` namespace, anchoring and the knowledge base in the ``laptop``
one; the only path between them is a point-to-point link whose impairment is chosen per run
(the paper's Wi-Fi: netem delay 50 ms, jitter 10 ms, 5 % loss):

* a veth pair with ``tc qdisc ... netem`` on both ends, where the kernel has sch_netem;
* otherwise (this project's VMs: kernel 6.18 without CONFIG_NET_SCH_NETEM) a TUN device in each
  namespace, joined by :mod:`tun_relay`, a userspace netem with the same parameters.

DDS across the namespaces: the processes inside them get ``ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET``
(not the test run's LOCALHOST), ``ROS_STATIC_PEERS`` naming the other end (unicast discovery, in
case multicast does not cross the link) and a Fast DDS profile with UDPv4 as the only transport.

Shared memory, found out: ``ip netns exec`` does not unshare /dev/shm, so Fast DDS's shared-memory
transport could in principle bypass the link. Fast DDS 2.14 (the Jazzy wheels) does not use it
here: it takes a participant for local, and offers it shared memory, only when both have the same
host id, an MD5 of the host name and the interfaces' IPv4 addresses (its utils/Host.hpp), and the
addresses differ between the namespaces. With the project's profile (shared memory first, then
UDP), nothing reaches the laptop side once the link is down; test_faults.py checks that in CI
with both profiles. The split still gives its processes the
UDP-only profile, so that the impaired link is the only path by construction, whatever a later
Fast DDS bases its host id on. Processes outside the namespaces are not affected.

Everything is named per run (``sailor_split_<pid>_<token>_robot``, veth / TUN names with the same
token, addresses in 10.213.x.y/30 that exist only inside the two namespaces) and removed by
:meth:`NetworkSplit.close`, also on failure; namespaces left by a run that died (its pid gone) are
removed by the next one. Nothing outside the project's own namespaces is touched.
"""

from __future__ import annotations

import os
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

NAMESPACE_PREFIX = "sailor_split_"
TUN_RELAY = Path(__file__).resolve().parent / "tun_relay.py"
COMMAND_TIMEOUT_SECONDS = 20.0
LEASE_SECONDS = 3  # as config/fastdds.xml: a killed node leaves the graph quickly

UDP_ONLY_PROFILE = f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- Written by test/ros/network_split.py for processes inside its namespaces: UDPv4 only, so that
     the impaired link between the namespaces is the only path (no shared memory). -->
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
    <transport_descriptor>
      <transport_id>split_udp</transport_id>
      <type>UDPv4</type>
    </transport_descriptor>
  </transport_descriptors>
  <participant profile_name="split_participant" is_default_profile="true">
    <rtps>
      <userTransports><transport_id>split_udp</transport_id></userTransports>
      <useBuiltinTransports>false</useBuiltinTransports>
      <builtin>
        <discovery_config>
          <leaseDuration><sec>{LEASE_SECONDS}</sec></leaseDuration>
          <leaseAnnouncement><sec>1</sec></leaseAnnouncement>
        </discovery_config>
      </builtin>
    </rtps>
  </participant>
</profiles>
"""


@dataclass(frozen=True)
class Impairment:
    """What the link does to every packet, in each direction (netem's ``delay D J loss L%``)."""

    delay_ms: float = 0.0
    jitter_ms: float = 0.0
    loss_percent: float = 0.0

    @property
    def is_none(self) -> bool:
        return self.delay_ms == 0.0 and self.jitter_ms == 0.0 and self.loss_percent == 0.0

    def netem_arguments(self) -> list[str]:
        return ["delay", f"{self.delay_ms:g}ms", f"{self.jitter_ms:g}ms", "loss", f"{self.loss_percent:g}%"]

    def __str__(self) -> str:
        if self.is_none:
            return "no impairment"
        return f"delay {self.delay_ms:g} ms, jitter {self.jitter_ms:g} ms, loss {self.loss_percent:g} %"


NO_IMPAIRMENT = Impairment()
TIAGO_WIFI = Impairment(delay_ms=50.0, jitter_ms=10.0, loss_percent=5.0)


class SplitUnavailable(RuntimeError):
    """Network namespaces cannot be made here; the message says why (for pytest.skip)."""


def _ip(*arguments: str, namespace: str | None = None, check: bool = True) -> subprocess.CompletedProcess[str]:
    command = ["ip", *(["netns", "exec", namespace, "ip"] if namespace else []), *arguments]
    result = subprocess.run(command, capture_output=True, text=True, timeout=COMMAND_TIMEOUT_SECONDS)
    if check and result.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {result.stderr.strip()}")
    return result


def unavailable_reason() -> str | None:
    """Why an impaired split cannot be built on this machine, or None when it can."""
    if sys.platform != "linux":
        return f"network namespaces are Linux only (this is {sys.platform})"
    if os.geteuid() != 0:
        return "network namespaces need root (ip netns add); run the test as root or in a privileged container"
    if shutil.which("ip") is None:
        return "the 'ip' command (iproute2) is not installed"
    probe = f"{NAMESPACE_PREFIX}{os.getpid()}_probe"
    created = _ip("netns", "add", probe, check=False)
    if created.returncode != 0:
        return f"'ip netns add' failed: {created.stderr.strip()}"
    try:
        if not _has_netem(probe) and not os.path.exists("/dev/net/tun"):
            return "the kernel has no sch_netem and there is no /dev/net/tun for the userspace relay"
    finally:
        _ip("netns", "del", probe, check=False)
    return None


def _has_netem(namespace: str) -> bool:
    """Try netem on a throw-away veth pair inside ``namespace``."""
    probe_a, probe_b = "svprobea", "svprobeb"
    if _ip("link", "add", probe_a, "type", "veth", "peer", "name", probe_b, namespace=namespace,
           check=False).returncode != 0:
        return False
    try:
        result = subprocess.run(
            ["ip", "netns", "exec", namespace, "tc", "qdisc", "add", "dev", probe_a, "root", "netem", "delay", "1ms"],
            capture_output=True, text=True, timeout=COMMAND_TIMEOUT_SECONDS)
        return result.returncode == 0
    except FileNotFoundError:  # no tc: no netem either
        return False
    finally:
        _ip("link", "del", probe_a, namespace=namespace, check=False)


def remove_stale_namespaces() -> list[str]:
    """Delete this project's namespaces whose creating process is gone, and the processes in them."""
    listed = _ip("netns", "list", check=False).stdout.split()
    removed = []
    for name in listed:
        if not name.startswith(NAMESPACE_PREFIX):
            continue
        owner = name.removeprefix(NAMESPACE_PREFIX).split("_", 1)[0]
        if not owner.isdigit() or _alive(int(owner)):
            continue
        for pid in subprocess.run(["ip", "netns", "pids", name], capture_output=True, text=True,
                                  timeout=COMMAND_TIMEOUT_SECONDS).stdout.split():
            _kill(int(pid))
        _ip("netns", "del", name, check=False)
        removed.append(name)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


@dataclass
class SplitProcess:
    """A process started inside one of the namespaces; ``stop()`` sends SIGINT and returns its exit code."""

    side: str
    process: subprocess.Popen[str]
    output: list[str] = field(default_factory=list)

    def stop(self, timeout: float = 20.0) -> int:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            out, _ = self.process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            out, _ = self.process.communicate()
        self.output.append(out or "")
        return self.process.returncode

    def kill(self) -> None:
        """SIGKILL the process and anything it started (it leads its own process group)."""
        try:
            os.killpg(self.process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    @property
    def text(self) -> str:
        return "".join(self.output)


class NetworkSplit:
    """Two namespaces, ``robot`` and ``laptop``, joined by one impaired link; a context manager.

    ``link``: ``"veth"`` (netem in the kernel; fails where sch_netem is missing), ``"tun"`` (the
    userspace relay) or ``"auto"`` (veth when there is no impairment or the kernel has netem,
    else tun). :attr:`link_kind` says which one was built and :attr:`impairment_by` who applies
    the impairment. ``profile``: the Fast DDS profile of the processes inside (UDP only unless
    given; the project's own, with shared memory, to check that it does not cross).
    """

    SIDES = ("robot", "laptop")

    def __init__(self, impairment: Impairment = NO_IMPAIRMENT, link: str = "auto", seed: int = 0,
                 profile: Path | None = None) -> None:
        if link not in ("auto", "veth", "tun"):
            raise ValueError(f"link must be auto, veth or tun, got {link!r}")
        self.impairment = impairment
        self._requested_link = link
        self._seed = seed
        token = secrets.token_hex(3)
        self.namespaces = {side: f"{NAMESPACE_PREFIX}{os.getpid()}_{token}_{side}" for side in self.SIDES}
        self.devices = {side: f"sv{token}{side[0]}" for side in self.SIDES}  # 9 characters, under IFNAMSIZ
        third_octet, fourth_octet = secrets.randbelow(256), 4 * secrets.randbelow(64)
        self.addresses = {"robot": f"10.213.{third_octet}.{fourth_octet + 1}",
                          "laptop": f"10.213.{third_octet}.{fourth_octet + 2}"}
        self.link_kind = ""
        self.impairment_by = ""
        self._relay: subprocess.Popen[str] | None = None
        self.relay_counts = ""
        self._processes: list[SplitProcess] = []
        self._folder = Path(tempfile.mkdtemp(prefix="sailor-split-"))
        if profile is None:
            profile = self._folder / "fastdds_udp_only.xml"
            profile.write_text(UDP_ONLY_PROFILE)
        self.profile = profile
        self._created: list[str] = []

    # --- building and removing ------------------------------------------------------------------

    def __enter__(self) -> NetworkSplit:
        try:
            self.open()
        except BaseException:
            self.close()
            raise
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    def open(self) -> None:
        remove_stale_namespaces()
        for side in self.SIDES:
            _ip("netns", "add", self.namespaces[side])
            self._created.append(self.namespaces[side])
            _ip("link", "set", "lo", "up", namespace=self.namespaces[side])
        link = self._requested_link
        if link == "auto":
            link = "veth" if self.impairment.is_none or _has_netem(self.namespaces["robot"]) else "tun"
        if link == "veth":
            self._build_veth()
        else:
            self._build_tun()

    def close(self) -> None:
        """Stop every process this split started, the relay, and delete the namespaces."""
        for handle in self._processes:
            if handle.process.poll() is None:
                handle.kill()
            try:
                handle.process.communicate(timeout=10.0)
            except (subprocess.TimeoutExpired, ValueError):
                pass
        if self._relay is not None:
            if self._relay.poll() is None:
                self._relay.terminate()
            try:
                out, _ = self._relay.communicate(timeout=10.0)
                self.relay_counts = (out or "").strip().splitlines()[-1] if (out or "").strip() else ""
            except subprocess.TimeoutExpired:
                self._relay.kill()
                self._relay.communicate()
            self._relay = None
        for namespace in self._created:
            for pid in subprocess.run(["ip", "netns", "pids", namespace], capture_output=True, text=True,
                                      timeout=COMMAND_TIMEOUT_SECONDS).stdout.split():
                _kill(int(pid))  # only processes inside this run's own namespace
            _ip("netns", "del", namespace, check=False)  # also removes the veth pair
        self._created.clear()
        shutil.rmtree(self._folder, ignore_errors=True)

    def _build_veth(self) -> None:
        robot, laptop = self.devices["robot"], self.devices["laptop"]
        _ip("link", "add", robot, "netns", self.namespaces["robot"], "type", "veth",
            "peer", "name", laptop, "netns", self.namespaces["laptop"])
        for side in self.SIDES:
            namespace, device = self.namespaces[side], self.devices[side]
            _ip("addr", "add", f"{self.addresses[side]}/30", "dev", device, namespace=namespace)
            _ip("link", "set", device, "up", namespace=namespace)
            _ip("route", "add", "224.0.0.0/4", "dev", device, namespace=namespace)  # DDS discovery multicast
            if not self.impairment.is_none:
                subprocess.run(["ip", "netns", "exec", namespace, "tc", "qdisc", "add", "dev", device, "root",
                                "netem", *self.impairment.netem_arguments()],
                               check=True, capture_output=True, text=True, timeout=COMMAND_TIMEOUT_SECONDS)
        self.link_kind = "veth"
        self.impairment_by = "kernel netem" if not self.impairment.is_none else "none"

    def _build_tun(self) -> None:
        impairment = self.impairment
        self._relay = subprocess.Popen(
            [sys.executable, str(TUN_RELAY), self.namespaces["robot"], self.devices["robot"],
             self.namespaces["laptop"], self.devices["laptop"], "--delay-ms", str(impairment.delay_ms),
             "--jitter-ms", str(impairment.jitter_ms), "--loss-percent", str(impairment.loss_percent),
             "--seed", str(self._seed)],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True)
        assert self._relay.stdout is not None
        line = self._relay.stdout.readline()
        if line.strip() != "ready":
            raise RuntimeError(f"the TUN relay did not start: {line}{self._relay.stdout.read()}")
        for side in self.SIDES:
            namespace, device = self.namespaces[side], self.devices[side]
            other = self.addresses["laptop" if side == "robot" else "robot"]
            _ip("addr", "add", self.addresses[side], "peer", f"{other}/32", "dev", device, namespace=namespace)
            _ip("link", "set", device, "mtu", "1500", "multicast", "on", "up", namespace=namespace)
            _ip("route", "add", "224.0.0.0/4", "dev", device, namespace=namespace)
        self.link_kind = "tun"
        self.impairment_by = "userspace relay (no sch_netem in this kernel)" if not impairment.is_none else "none"

    # --- using it -------------------------------------------------------------------------------

    def environment(self, side: str) -> dict[str, str]:
        """The environment of a ROS process on ``side``: discovery over the link, UDP only."""
        other = self.addresses["laptop" if side == "robot" else "robot"]
        return {
            **os.environ,
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET",
            "ROS_STATIC_PEERS": other,
            "FASTRTPS_DEFAULT_PROFILES_FILE": str(self.profile),
            "PYTHONUNBUFFERED": "1",
        }

    def start(self, side: str, command: Sequence[str]) -> SplitProcess:
        """Run ``command`` inside ``side``'s namespace, its output captured; stopped by close()."""
        process = subprocess.Popen(
            ["ip", "netns", "exec", self.namespaces[side], *command],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True,
            env=self.environment(side), start_new_session=True)
        handle = SplitProcess(side, process)
        self._processes.append(handle)
        return handle

    def set_link(self, up: bool) -> None:
        """Take the link down (or up again) on the robot side: nothing crosses while it is down."""
        _ip("link", "set", self.devices["robot"], "up" if up else "down", namespace=self.namespaces["robot"])
