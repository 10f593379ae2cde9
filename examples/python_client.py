#!/usr/bin/env python3
"""A NavCam pose-protocol client using the Python standard library only.

Encodes protocol v1 messages (docs/protocol.md) with struct and zlib, and
streams a trajectory to `navcam serve`: over UDP at real time, or over TCP in
lock-step, waiting for each frame.

    python3 examples/python_client.py traj.csv --lockstep
    python3 examples/python_client.py --circle 20          # a built-in orbit

Trajectory rows: t_s, cam_x_m, cam_y_m, cam_z_m, q_w, q_x, q_y, q_z,
sun_x, sun_y, sun_z[, capture].
"""
import argparse
import math
import socket
import struct
import sys
import time
import zlib

MAGIC, VERSION = 0x4D41434E, 1
POSE, TRIGGER, FRAME = 1, 2, 3
SUN_POSITION, BODY_POSE, CAMERA_RATES, BODY_RATES, CAPTURE, EXPOSURE, GAIN = (1 << i for i in range(7))


def encode(msg_type, sequence, flags, t_ns, cam_pos=(0, 0, 0), cam_q=(1, 0, 0, 0), sun=(1, 0, 0),
           exposure_s=None, gain_db=None):
    """One message as bytes (no TCP length prefix)."""
    body = struct.pack("<q", t_ns)
    if msg_type == POSE:
        body += struct.pack("<3d4d3d", *cam_pos, *cam_q, *sun)
    if exposure_s is not None:
        flags |= EXPOSURE
        body += struct.pack("<d", exposure_s)
    if gain_db is not None:
        flags |= GAIN
        body += struct.pack("<d", gain_db)
    length = 24 + len(body) + 4
    head = struct.pack("<IHHIIII", MAGIC, VERSION, msg_type, length, sequence, flags, 0)
    data = head + body
    return data + struct.pack("<I", zlib.crc32(data) & 0xFFFFFFFF)


def read_frame_answer(sock):
    """The next FRAME message on a TCP connection: (sequence, frame, status)."""
    def recv_exact(n):
        buf = b""
        while len(buf) < n:
            chunk = sock.recv(n - len(buf))
            if not chunk:
                raise ConnectionError("connection closed")
            buf += chunk
        return buf
    (length,) = struct.unpack("<I", recv_exact(4))
    msg = recv_exact(length)
    magic, version, mtype, _, sequence, _, _ = struct.unpack_from("<IHHIIII", msg)
    if magic != MAGIC or mtype != FRAME or zlib.crc32(msg[:-4]) & 0xFFFFFFFF != struct.unpack_from("<I", msg, length - 4)[0]:
        raise ValueError("not a FRAME message")
    _, frame, status = struct.unpack_from("<qQI", msg, 24)
    return sequence, frame, status


def look_at(eye, target, up=(0, 0, 1)):
    """Camera attitude (camera -> scene, +Z boresight, +Y down) looking at target."""
    def sub(a, b): return [a[i] - b[i] for i in range(3)]
    def cross(a, b): return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    def unit(a):
        n = math.sqrt(sum(x * x for x in a))
        return [x / n for x in a]
    z = unit(sub(target, eye))
    x = unit(cross([-u for u in up], z))
    y = cross(z, x)
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = 2 * math.sqrt(1 + tr)
        return (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0] * 4
    q[0] = (m[k][j] - m[j][k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (m[j][i] + m[i][j]) / s
    q[1 + k] = (m[k][i] + m[i][k]) / s
    return tuple(q)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("trajectory", nargs="?", help="CSV trajectory")
    ap.add_argument("--circle", type=int, metavar="N", help="N poses on a 6 km circle around the default asteroid")
    ap.add_argument("--lockstep", action="store_true", help="TCP, wait for each frame")
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int)
    a = ap.parse_args()
    rows = []
    if a.circle:
        for i in range(a.circle):
            ang = 2 * math.pi * i / a.circle
            eye = (6000 * math.sin(ang), -6000 * math.cos(ang), 500.0)
            rows.append((float(i), eye, look_at(eye, (0, 0, 0)), (0.643, -0.766, 0.0), 1))
    elif a.trajectory:
        with open(a.trajectory) as f:
            for line in f:
                v = line.strip().split(",")
                try:
                    vals = [float(x) for x in v]
                except ValueError:
                    continue  # a header
                rows.append((vals[0], vals[1:4], vals[4:8], vals[8:11], int(vals[11]) if len(vals) > 11 else 1))
    else:
        ap.error("give a trajectory file or --circle N")
    port = a.port or (5751 if a.lockstep else 5750)
    sock = socket.create_connection((a.host, port)) if a.lockstep else socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    if a.lockstep:  # small messages sent at once, not held back for an acknowledgement (docs/protocol.md)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    t0 = time.monotonic()
    for seq, (t, pos, q, sun, cap) in enumerate(rows, start=1):
        msg = encode(POSE, seq, CAPTURE if cap else 0, int(round(t * 1e9)), pos, q, sun)
        if a.lockstep:
            sock.sendall(struct.pack("<I", len(msg)) + msg)
            if cap:
                s, frame, status = read_frame_answer(sock)
                print(f"pose {seq}: frame {frame} {'delivered' if status == 0 else 'dropped'}")
        else:
            delay = (t - rows[0][0]) - (time.monotonic() - t0)
            if delay > 0:
                time.sleep(delay)
            sock.sendto(msg, (a.host, port))
    sock.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
