#!/usr/bin/env python3
"""Bytes no HTTP client sends, at the rig's endpoint: random garbage, a 40 KB URL and header,
a chunked body over the limit, a Content-Length of 100 MB, 40 idle connections (the limit is
32). usage: http_garbage.py PORT SEED. Prints one JSON object: answer status line -> count.
tests/fw/test_fw_http.c checks the rig answers normally afterwards."""
import json
import random
import socket
import sys
import time

port, seed = int(sys.argv[1]), int(sys.argv[2])
rnd = random.Random(seed)
seen = {}


def send(data):
    s = socket.create_connection(("127.0.0.1", port), timeout=3)
    try:
        s.sendall(data)
        line = s.recv(200).split(b"\r\n", 1)[0].decode("latin-1")[:12] or "closed"
    except OSError as e:
        line = type(e).__name__
    finally:
        s.close()
    seen[line] = seen.get(line, 0) + 1


for _ in range(60):
    send(bytes(rnd.getrandbits(8) for _ in range(rnd.randint(1, 600))) + b"\r\n\r\n")
host = b"Host: 127.0.0.1\r\n"
send(b"GET /" + b"a" * 40000 + b" HTTP/1.1\r\n" + host + b"\r\n")
send(b"GET / HTTP/1.1\r\n" + host + b"X: " + b"b" * 40000 + b"\r\n\r\n")
send(b"POST /api/scene HTTP/1.1\r\n" + host + b"Content-Type: application/json\r\n"
     b"Transfer-Encoding: chunked\r\n\r\n" + (b"1000\r\n" + b" " * 4096 + b"\r\n") * 3 +
     b"0\r\n\r\n")
send(b"POST /api/controls/dimmer HTTP/1.1\r\n" + host + b"Content-Type: application/json\r\n"
     b"Content-Length: 100000000\r\n\r\n{")
socks = []
for _ in range(40):
    try:
        socks.append(socket.create_connection(("127.0.0.1", port), timeout=2))
    except OSError as e:
        seen["connect " + type(e).__name__] = seen.get("connect " + type(e).__name__, 0) + 1
time.sleep(0.3)
for s in socks:
    s.close()
print(json.dumps(seen, sort_keys=True))
