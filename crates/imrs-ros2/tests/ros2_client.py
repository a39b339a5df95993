"""An outside ROS 2 client of an IMRS cell, written only from rmw_zenoh's conventions: its
key expressions, liveliness tokens, CDR payloads and 33-byte attachment.

Usage: ros2_client.py ENDPOINT

Lists the ROS 2 graph (the liveliness tokens under @ros2_lv/0), finds the chip_cell node,
its /joint_states publisher and its /status service; subscribes to /joint_states on the key
the token gives and reads one sensor_msgs/JointState; calls /status (std_srvs/Trigger) with
its own sequence number and GID, and checks the reply's attachment carries them back.
Prints one line per finding; exits non-zero on anything unexpected.
"""

import queue
import struct
import sys
import time

import zenoh

HEADER = b"\x00\x01\x00\x00"  # CDR, little-endian


class Cdr:
    """A little-endian CDR reader; alignment counts from the byte after the header."""

    def __init__(self, payload):
        assert payload[:4] == HEADER, payload[:4]
        self.body, self.at = payload[4:], 0

    def read(self, fmt):
        size = struct.calcsize(fmt)
        self.at += -self.at % size
        (value,) = struct.unpack_from(fmt, self.body, self.at)
        self.at += size
        return value

    def string(self):
        length = self.read("<I")
        text = self.body[self.at : self.at + length - 1].decode()
        self.at += length
        return text

    def sequence(self, item):
        return [item() for _ in range(self.read("<I"))]


def graph(session):
    """Every token of the ROS 2 graph of domain 0, split into its chunks."""
    replies = session.liveliness().get("@ros2_lv/0/**", timeout=2.0)
    return [str(reply.ok.key_expr).split("/") for reply in replies if reply.ok is not None]


def data_key(token):
    """The key expression of an endpoint's data, from its token."""
    topic, dds_type, type_hash = token[9].replace("%", "/"), token[10], token[11]
    return f"{token[1]}/{topic.strip('/')}/{dds_type}/{type_hash}"


def main():
    endpoint = sys.argv[1]
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", f'["{endpoint}"]')
    session = zenoh.open(config)

    # The graph: a node, a publisher and a service server of the cell.
    for _ in range(100):
        tokens = graph(session)
        kinds = {token[5] for token in tokens}
        if {"NN", "MP"} <= kinds and any(t[9:10] == ["%status"] for t in tokens):
            break
        time.sleep(0.1)
    else:
        sys.exit(f"the cell's graph never appeared: {tokens}")
    node = next(t for t in tokens if t[5] == "NN")
    print(f"node {node[7].replace('%', '/')}{node[8]}")
    publisher = next(t for t in tokens if t[5] == "MP")
    server = next(t for t in tokens if t[5] == "SS" and t[9] == "%status")
    for token in (publisher, server):
        assert token[2] == node[2] and token[3] == node[3], "an endpoint of another node"
        print(f"{token[5]} {token[9].replace('%', '/')} {token[10]} {token[11]}")

    # A joint state, on the key the publisher's token gives.
    samples = queue.Queue()
    subscriber = session.declare_subscriber(
        data_key(publisher),
        lambda sample: samples.put((sample.payload.to_bytes(), sample.attachment)),
    )
    try:
        payload, attachment = samples.get(timeout=10.0)
    except queue.Empty:
        sys.exit("no joint state")
    assert attachment is not None and len(attachment.to_bytes()) == 33, attachment
    cdr = Cdr(payload)
    sec, nanosec, frame = cdr.read("<i"), cdr.read("<I"), cdr.string()
    names = cdr.sequence(cdr.string)
    positions = cdr.sequence(lambda: cdr.read("<d"))
    print(f"joint_states {frame} {names} {positions}")
    subscriber.undeclare()

    # The status service, as a ROS 2 client calls it.
    gid = bytes(range(16))
    asked = struct.pack("<qqB", 7, time.time_ns(), 16) + gid
    replies = list(
        session.get(
            data_key(server),
            payload=HEADER + b"\x00",  # Trigger's request: its one placeholder byte
            attachment=asked,
            target=zenoh.QueryTarget.ALL_COMPLETE,
            consolidation=zenoh.ConsolidationMode.NONE,
            timeout=10.0,
        )
    )
    assert len(replies) == 1, replies
    reply = replies[0].ok
    assert reply is not None, replies[0].err.payload.to_bytes()
    answered = reply.attachment.to_bytes()
    sequence_number, _, length = struct.unpack_from("<qqB", answered)
    assert (sequence_number, length, answered[17:]) == (7, 16, gid), answered
    cdr = Cdr(reply.payload.to_bytes())
    success, message = cdr.read("<?"), cdr.string()
    print(f"status {success} {message}")
    session.close()


if __name__ == "__main__":
    main()
