#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Writes the fuzzers' seed corpus (tests/fuzz/corpus/). The files are
# committed; rerun this only to change them. Stream parser seeds start with
# the two control bytes fuzz_stream_parser.hpp reads (settings, chunk seed).
import os

HERE = os.path.dirname(os.path.abspath(__file__))

def table():
    t = []
    for i in range(256):
        c = i << 8
        for _ in range(8):
            c = ((c << 1) ^ 0x1021) if c & 0x8000 else c << 1
        t.append(c & 0xFFFF)
    return t
T = table()

def crc(b):
    c = 0xFFFF
    for x in b:
        c = T[(c ^ x) & 0xFF] ^ (c >> 8)
    return c

def packet(pid, payload=b""):
    body = b"\xaa\xaa\xaa" + bytes([pid]) + len(payload).to_bytes(2, "little") + payload
    return body + crc(body).to_bytes(2, "little")

def reply(pid, status=0, payload=b""):
    return packet(pid, status.to_bytes(2, "little") + payload)

def matrix_info(res_x, res_y):
    return reply(0x30, 0, b"".join(v.to_bytes(2, "little") for v in (res_x, res_y, 340, 340, 4095)))

def frame(ts, rows, cols, base=0):
    texels = b"".join(((base + 37 * i) % 4096).to_bytes(2, "little") for i in range(rows * cols))
    return packet(0x00, ts.to_bytes(4, "little") + b"\x00" + texels)

def write(kind, name, data):
    d = os.path.join(HERE, "corpus", kind)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)

# --- stream parser -------------------------------------------------------
wts = matrix_info(6, 14)
write("stream_parser", "golden_commands", b"\x01\x00" + packet(0x30) + packet(0x21, b"\x00\xc8\x00"))
write("stream_parser", "session_14x6", b"\x01\x07" + wts + reply(0x21) + frame(1000, 14, 6) + frame(1200, 14, 6, 5) + reply(0x22))
write("stream_parser", "learn_grid", b"\x00\x03" + frame(1, 14, 6) + wts + frame(2, 14, 6, 9) + frame(3, 6, 14, 1))
bad = bytearray(frame(7, 2, 3)); bad[12] ^= 0x04
write("stream_parser", "junk_and_damage_2x3", b"\x02\x11" + b"\x13\xaa\xaa\x00\xaa" + bytes(bad) + frame(8, 2, 3)[:9] + frame(9, 2, 3) + b"\xaa\xaa")
write("stream_parser", "oversize_bound_200", b"\x05\x21" + b"\xaa\xaa\xaa\x00\x2c\x01" + frame(4, 14, 6))
write("stream_parser", "huge_size_field", b"\x0d\x02" + b"\xaa\xaa\xaa\x00\x60\xea\x01\x02" + frame(5, 14, 6))
write("stream_parser", "nested_loop", b"\x03\x05" + packet(0x06, reply(0x23)) + frame(6, 1, 1))
write("stream_parser", "out_of_range", b"\x11\x09" + packet(0x00, b"\x01\x00\x00\x00\x00" + b"\xff\xff" * 84) + packet(0x00, b"\x01\x00\x00\x00\x00" + b"\x00\x10" * 84))
def nested_headers(length):
    b = bytearray(b"\x55" * length)
    for p in range(0, length - 7, 6):  # each header announces a packet ending at the block's end
        b[p:p + 6] = b"\xaa\xaa\xaa\x01" + (length - p - 8).to_bytes(2, "little")
    return bytes(b)
# Worst case of the framer's inner-packet check (was O(L^3), now one CRC per header).
write("stream_parser", "nested_headers", b"\x0d\x04" + nested_headers(600) + reply(0x23))
write("stream_parser", "malformed", b"\x01\x01" + packet(0x00, b"\x01\x02") + packet(0x23, b"\x00") + packet(0x00, b"\x01\x02\x03\x04\x05\x06"))

# --- dataset CSV ---------------------------------------------------------
def text(kind, name, s):
    write(kind, name, s.encode("utf-8"))

text("dataset_csv", "full_2x2.csv",
     "# sensor: WTS rows=2 cols=2 pitch_m=0.0034\n# note\n"
     "object,exploration,frame,t,x,y,z,qw,qx,qy,qz,p0_0,p0_1,p1_0,p1_1\n"
     "mug,0,0,1.5,0.1,0.2,0.3,1,0,0,0,0,12.5,4095,3\n"
     "mug,0,1,1.7,0.11,0.2,0.3,0,1,0,0,1,2,3,4\n"
     "bowl,3,0,2,1e-3,-2,0,0.5,0.5,0.5,0.5,0,0,0,0\n")
text("dataset_csv", "minimal_1x1.csv", "object,exploration,frame,x,y,z,p0_0\na,1,2,0,0,0,7\n")
text("dataset_csv", "reordered_extra.csv", "p0_1,z,note,y,frame,x,p0_0,exploration,object\n1,0,hello,0,0,0,2,5,cup\n")
write("dataset_csv", "crlf_bom.csv", b"\xef\xbb\xbf# c\r\nobject,exploration,frame,x,y,z,p0_0\r\nb,0,0,1,2,3,0\r\n")
text("dataset_csv", "hole.csv", "object,exploration,frame,x,y,z,p0_0,p1_1\na,0,0,0,0,0,1,1\n")
text("dataset_csv", "negative.csv", "object,exploration,frame,x,y,z,p0_0\na,0,0,0,0,0,-1\n")
text("dataset_csv", "nan.csv", "object,exploration,frame,x,y,z,p0_0\na,0,0,nan,0,0,1\n")
text("dataset_csv", "partial_quaternion.csv", "object,exploration,frame,x,y,z,qw,qx,p0_0\na,0,0,0,0,0,1,0,1\n")
text("dataset_csv", "field_count.csv", "object,exploration,frame,x,y,z,p0_0\na,0,0,0,0,0\n")
text("dataset_csv", "missing_column.csv", "object,frame,x,y,z,p0_0\na,0,0,0,0,1\n")
text("dataset_csv", "float_frame.csv", "object,exploration,frame,x,y,z,p0_0\na,0,1.5,0,0,0,1\n")
