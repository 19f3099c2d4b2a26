"""Listening beyond loopback next to the local daemon.

The daemon holds ``tcp/127.0.0.1:7447``; a robot that listens on ``tcp/0.0.0.0:7447`` (the
port Zenoh and seed 002's laptop expect) cannot bind the wildcard while the daemon holds
that port on loopback. Listening on each of the machine's other addresses instead reaches
the same laptops and leaves loopback to the daemon.
"""

from __future__ import annotations

import fcntl
import ipaddress
import socket
import struct
from pathlib import Path

from roverlab.core.errors import TransportError

__all__ = ["host_addresses", "split_wildcard_listen"]

_SIOCGIFADDR = 0x8915
_WILDCARDS = {"0.0.0.0": 4, "[::]": 6, "::": 6}


def _ipv4_addresses() -> list[str]:
    found: list[str] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for _, name in socket.if_nameindex():
            req = struct.pack("256s", name.encode()[:15])
            try:
                reply = fcntl.ioctl(s.fileno(), _SIOCGIFADDR, req)
            except OSError:  # no IPv4 address on this interface
                continue
            found.append(socket.inet_ntoa(reply[20:24]))
    return found


def _ipv6_addresses() -> list[str]:
    path = Path("/proc/net/if_inet6")
    if not path.exists():
        return []
    found = []
    for line in path.read_text().splitlines():
        raw = line.split()[0]
        found.append(str(ipaddress.IPv6Address(bytes.fromhex(raw))))
    return found


def host_addresses(family: int) -> list[str]:
    """This machine's addresses of an IP family (4 or 6), without loopback and IPv6
    link-local ones (those need a scope), in interface order."""
    raw = _ipv4_addresses() if family == 4 else _ipv6_addresses()
    keep = []
    for text in raw:
        addr = ipaddress.ip_address(text)
        if addr.is_loopback or (addr.version == 6 and addr.is_link_local):
            continue
        if text not in keep:
            keep.append(text)
    return keep


def split_wildcard_listen(listen: tuple[str, ...], daemon: str) -> tuple[str, ...]:
    """``listen`` with each wildcard TCP endpoint on the daemon's port replaced by one
    endpoint per address of the machine (IPv4 for ``0.0.0.0``; both families for ``[::]``,
    which covers IPv4 too). Other endpoints pass unchanged.

    Raises:
        TransportError: a wildcard to split, and no address but loopback to listen on.
    """
    d_proto, _, d_addr = daemon.partition("/")
    d_port = d_addr.rpartition(":")[2]
    out: list[str] = []
    for ep in listen:
        proto, _, addr = ep.partition("/")
        host, _, rest = addr.rpartition(":")
        port, sep, meta = rest.partition("#")
        family = _WILDCARDS.get(host)
        if proto != "tcp" or d_proto != "tcp" or family is None or port != d_port:
            out.append(ep)
            continue
        hosts = host_addresses(4) + (host_addresses(6) if family == 6 else [])
        if not hosts:
            raise TransportError(
                f"cannot listen on {ep}: this machine has no address besides loopback "
                "(is the network up?)"
            )
        for h in hosts:
            shown = f"[{h}]" if ":" in h else h
            out.append(f"tcp/{shown}:{port}{sep}{meta}")
    return tuple(out)
