"""A ROS 2 peer that is not ours, written only from rmw_zenoh's conventions: it publishes
std_msgs/String commands on /commands and serves example_interfaces/AddTwoInts on
/add_two_ints, on the keys ROS 2's published type hashes give, with rmw_zenoh's attachment.
Prints "ready" once both are declared; runs until its standard input closes.

Usage: ros2_peer.py ENDPOINT
"""

import struct
import sys
import threading
import time

import zenoh

HEADER = b"\x00\x01\x00\x00"  # CDR, little-endian
COMMANDS = (
    "0/commands/std_msgs::msg::dds_::String_/"
    "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
)
ADD = (
    "0/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/"
    "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
)
GID = bytes(range(16, 32))


def attachment(sequence_number, gid):
    return struct.pack("<qqB", sequence_number, time.time_ns(), 16) + gid


def main():
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", f'["{sys.argv[1]}"]')
    session = zenoh.open(config)

    def add(query):
        asked = query.attachment.to_bytes()
        sequence_number, _, _ = struct.unpack_from("<qqB", asked)
        a, b = struct.unpack_from("<qq", query.payload.to_bytes(), 4)
        query.reply(
            query.key_expr,
            HEADER + struct.pack("<q", a + b),
            attachment=attachment(sequence_number, asked[17:]),
        )

    server = session.declare_queryable(ADD, add, complete=True)
    done = threading.Event()

    def publish():
        n = 0
        while not done.is_set():
            n += 1
            text = f"start {n}".encode() + b"\x00"
            payload = HEADER + struct.pack("<I", len(text)) + text
            session.put(COMMANDS, payload, attachment=attachment(n, GID))
            time.sleep(0.05)

    publishing = threading.Thread(target=publish)
    publishing.start()
    print("ready", flush=True)
    sys.stdin.read()
    done.set()
    publishing.join()
    server.undeclare()
    session.close()


if __name__ == "__main__":
    main()
