"""Listening TCP sockets of a process and its descendants, from /proc (Linux): what a test
of "nothing listens beyond loopback" needs, with no dependency (iproute2's `ss` may be
absent)."""

import ipaddress
import os
import socket


def _children():
    """{ppid: [pid, ...]} of every process visible in /proc."""
    out = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % name, "rb") as f:
                stat = f.read()
        except OSError:
            continue
        # pid (comm) state ppid ...: comm may hold spaces and parentheses.
        fields = stat[stat.rfind(b")") + 2:].split()
        out.setdefault(int(fields[1]), []).append(int(name))
    return out


def process_tree(pid):
    """pid and every descendant of it."""
    children = _children()
    tree, todo = [], [pid]
    while todo:
        p = todo.pop()
        tree.append(p)
        todo.extend(children.get(p, []))
    return tree


def _socket_inodes(pid):
    inodes = set()
    try:
        names = os.listdir("/proc/%d/fd" % pid)
    except OSError:
        return inodes
    for fd in names:
        try:
            target = os.readlink("/proc/%d/fd/%s" % (pid, fd))
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(int(target[8:-1]))
    return inodes


def _address(hex_address, family):
    host, port = hex_address.split(":")
    raw = bytes.fromhex(host)
    if family == socket.AF_INET:
        ip = ipaddress.IPv4Address(raw[::-1])
    else:  # four 32-bit words, each in host (little-endian) order
        ip = ipaddress.IPv6Address(b"".join(raw[i:i + 4][::-1] for i in range(0, 16, 4)))
    return ip, int(port, 16)


def listening(pids=None):
    """[(ip, port, pid)] of the TCP sockets in LISTEN state ("0A" in /proc/net/tcp*) owned by
    `pids` (all processes when None)."""
    owners = {}
    for pid in (pids if pids is not None else [int(n) for n in os.listdir("/proc")
                                               if n.isdigit()]):
        for inode in _socket_inodes(pid):
            owners[inode] = pid
    found = []
    for path, family in (("/proc/net/tcp", socket.AF_INET), ("/proc/net/tcp6", socket.AF_INET6)):
        try:
            with open(path) as f:
                lines = f.readlines()[1:]
        except OSError:
            continue
        for line in lines:
            cols = line.split()
            if cols[3] != "0A":
                continue
            inode = int(cols[9])
            if inode in owners:
                ip, port = _address(cols[1], family)
                found.append((ip, port, owners[inode]))
    return found


def exposed(entries):
    """The entries of listening() not bound to a loopback address (127.0.0.0/8, ::1, or
    IPv4-mapped loopback)."""
    def loopback(ip):
        mapped = getattr(ip, "ipv4_mapped", None)
        return ip.is_loopback or (mapped is not None and mapped.is_loopback)
    return [e for e in entries if not loopback(e[0])]
