"""An outside client of an IMRS cell on zenoh, written only from the documented wire format.

Usage: outside_client.py ENDPOINT CELL

Asks the DOUBLE port (u64 -> u64, owned by DOUBLER) to double 21, queries the STATUS port
(a RESPONSE port, string -> string), and asks DOUBLE as a module off its user list. Then
listens to the ALARM port (a SENDALL port of strings, answered with a u32, owned by LINE)
as module PYTHON: connects, holds its token, reads one broadcast and answers it with its
length. Prints one line per answer; exits non-zero on anything unexpected.
"""

import struct
import sys
import threading
import time

import zenoh

HEADER = b"\x00\x01\x00\x00"  # CDR, little-endian


def cdr_u64(n):
    return HEADER + struct.pack("<Q", n)


def cdr_string(s):
    data = s.encode() + b"\x00"
    return HEADER + struct.pack("<I", len(data)) + data


def read_u64(payload):
    assert payload[:4] == HEADER, payload
    return struct.unpack("<Q", payload[4:12])[0]


def read_string(payload):
    assert payload[:4] == HEADER, payload
    (length,) = struct.unpack("<I", payload[4:8])
    return payload[8 : 8 + length - 1].decode()


def ask(session, key, payload, module):
    # The asking module is the key's last chunk.
    key = f"{key}/{module}"
    replies = list(session.get(key, payload=payload, timeout=10.0))
    assert len(replies) == 1, f"{key}: {len(replies)} replies"
    reply = replies[0]
    if reply.ok is not None:
        return True, reply.ok.payload.to_bytes()
    return False, reply.err.payload.to_bytes().decode()


def main():
    endpoint, cell = sys.argv[1], sys.argv[2]
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", f'["{endpoint}"]')
    session = zenoh.open(config)
    # The owner's liveliness token says the port is served.
    for _ in range(100):
        if list(session.liveliness().get(f"imrs/{cell}/live/DOUBLE", timeout=1.0)):
            break
        time.sleep(0.1)
    else:
        sys.exit("DOUBLE's owner never seen")
    ok, doubled = ask(session, f"imrs/{cell}/port/DOUBLE", cdr_u64(21), "PYTHON")
    assert ok, doubled
    print(f"DOUBLE 21 -> {read_u64(doubled)}")
    ok, status = ask(session, f"imrs/{cell}/port/STATUS", cdr_string("status"), "PYTHON")
    assert ok, status
    print(f"STATUS -> {read_string(status)}")
    ok, refused = ask(session, f"imrs/{cell}/port/DOUBLE", cdr_u64(1), "ROGUE")
    assert not ok, refused
    print(f"ROGUE refused: {refused}")

    # A listener of ALARM: its deliver queryable first, then its token, then its connection.
    heard = []
    done = threading.Event()

    def on_broadcast(query):
        alarm = read_string(query.payload.to_bytes())
        heard.append((query.attachment.to_bytes().decode(), alarm))
        query.reply(query.key_expr, HEADER + struct.pack("<I", len(alarm)))
        done.set()

    deliver = session.declare_queryable(f"imrs/{cell}/deliver/ALARM/PYTHON", on_broadcast)
    token = session.liveliness().declare_token(f"imrs/{cell}/user/ALARM/PYTHON")
    ok, connected = ask(session, f"imrs/{cell}/connect/ALARM", b"", "PYTHON")
    assert ok, connected
    if not done.wait(10.0):
        sys.exit("no broadcast on ALARM")
    owner, alarm = heard[0]
    print(f"ALARM from {owner}: {alarm}")
    token.undeclare()
    deliver.undeclare()
    session.close()


if __name__ == "__main__":
    main()
