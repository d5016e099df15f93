"""A userspace netem: two network namespaces joined through TUN devices, with delay, jitter and loss.

Used by :mod:`network_split` where the kernel has no ``sch_netem`` (``tc qdisc add ... netem``
answers "Specified qdisc kind is unknown", as on this project's Firecracker VMs). Run as a
process of its own (root)::

    python tun_relay.py NAMESPACE_A DEVICE_A NAMESPACE_B DEVICE_B --delay-ms 50 --jitter-ms 10 --loss-percent 5

It creates one TUN device in each namespace (``setns`` into each in turn before opening
``/dev/net/tun``), prints ``ready`` once both exist, and then copies every IP packet read from
one device into the other, after netem's default impairment: each packet is dropped with the
loss probability, else delayed by a uniform draw in [delay - jitter, delay + jitter], so
packets may be reordered as with netem. The caller gives the devices their addresses. The
devices are not persistent: they vanish with this process, so a killed relay leaves nothing
behind. On SIGTERM or SIGINT it prints one JSON line of counts and exits.
"""

from __future__ import annotations

import argparse
import ctypes
import fcntl
import heapq
import json
import os
import random
import select
import signal
import struct
import sys
import time

CLONE_NEWNET = 0x40000000
TUNSETIFF = 0x400454CA
IFF_TUN = 0x0001
IFF_NO_PI = 0x1000
MAXIMUM_PACKET_BYTES = 65535
NETNS_FOLDER = "/run/netns"


def open_tun_device(namespace: str, device: str) -> int:
    """Enter ``namespace`` and create the TUN device ``device`` there; return its file descriptor.

    A TUN device belongs to the network namespace of the process that opened /dev/net/tun, so
    this process enters each namespace in turn; the descriptors keep working from anywhere.
    """
    libc = ctypes.CDLL(None, use_errno=True)
    with open(os.path.join(NETNS_FOLDER, namespace)) as handle:
        if libc.setns(handle.fileno(), CLONE_NEWNET) != 0:
            error = ctypes.get_errno()
            raise OSError(error, f"setns into network namespace {namespace!r}: {os.strerror(error)}")
    descriptor = os.open("/dev/net/tun", os.O_RDWR | os.O_NONBLOCK)
    fcntl.ioctl(descriptor, TUNSETIFF, struct.pack("16sH", device.encode(), IFF_TUN | IFF_NO_PI))
    return descriptor


class Impairer:
    """Decides each packet's fate: dropped (None) or the delay in seconds before it is passed on."""

    def __init__(self, delay_ms: float, jitter_ms: float, loss_percent: float, seed: int) -> None:
        self._delay, self._jitter = delay_ms / 1000.0, jitter_ms / 1000.0
        self._loss = loss_percent / 100.0
        self._random = random.Random(seed)

    def delay_of_next_packet(self) -> float | None:
        if self._loss > 0.0 and self._random.random() < self._loss:
            return None
        if self._jitter <= 0.0:
            return self._delay
        return max(0.0, self._random.uniform(self._delay - self._jitter, self._delay + self._jitter))


def relay(side_a: int, side_b: int, impairer: Impairer, stop: list[bool]) -> dict[str, int]:
    """Copy packets both ways until ``stop[0]`` is set; return the counts."""
    other = {side_a: side_b, side_b: side_a}
    pending: list[tuple[float, int, int, bytes]] = []  # (due time, sequence, destination, packet)
    counts = {"forwarded": 0, "dropped": 0, "write_errors": 0}
    sequence = 0
    while not stop[0]:
        now = time.monotonic()
        timeout = min(0.2, max(0.0, pending[0][0] - now)) if pending else 0.2
        try:
            readable, _, _ = select.select([side_a, side_b], [], [], timeout)
        except InterruptedError:
            continue
        now = time.monotonic()
        for source in readable:
            while True:
                try:
                    packet = os.read(source, MAXIMUM_PACKET_BYTES)
                except BlockingIOError:
                    break
                delay = impairer.delay_of_next_packet()
                if delay is None:
                    counts["dropped"] += 1
                    continue
                sequence += 1
                heapq.heappush(pending, (now + delay, sequence, other[source], packet))
        now = time.monotonic()
        while pending and pending[0][0] <= now:
            _, _, destination, packet = heapq.heappop(pending)
            try:
                os.write(destination, packet)
                counts["forwarded"] += 1
            except OSError:  # the device is down or its queue full: a lost packet, as on a real link
                counts["write_errors"] += 1
    return counts


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("namespace_a")
    parser.add_argument("device_a")
    parser.add_argument("namespace_b")
    parser.add_argument("device_b")
    parser.add_argument("--delay-ms", type=float, default=0.0)
    parser.add_argument("--jitter-ms", type=float, default=0.0)
    parser.add_argument("--loss-percent", type=float, default=0.0)
    parser.add_argument("--seed", type=int, default=0)
    arguments = parser.parse_args(argv)
    stop = [False]

    def request_stop(*_: object) -> None:
        stop[0] = True

    signal.signal(signal.SIGTERM, request_stop)
    signal.signal(signal.SIGINT, request_stop)
    side_a = open_tun_device(arguments.namespace_a, arguments.device_a)
    side_b = open_tun_device(arguments.namespace_b, arguments.device_b)
    print("ready", flush=True)
    impairer = Impairer(arguments.delay_ms, arguments.jitter_ms, arguments.loss_percent, arguments.seed)
    counts = relay(side_a, side_b, impairer, stop)
    print(json.dumps(counts), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
