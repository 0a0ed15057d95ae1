"""The socket byte counting of bench/ws_traffic.py, on ss output as iproute2 6.1 prints it."""

from __future__ import annotations

import math

from bench.ws_traffic import bytes_in_window, kilobytes_per_s, parse_ss

SS = """\
0      0      127.0.0.1:8080 127.0.0.1:35494
\t bbr wscale:10,10 rto:208 rtt:5.772/11.501 mss:47616 cwnd:14 bytes_sent:134464 \
bytes_retrans:34464 bytes_acked:100000 segs_out:4 segs_in:5 data_segs_out:4
0      0      127.0.0.1:8080 127.0.0.1:35500
\t cubic wscale:7,7 rto:204 rtt:0.01/0.005 mss:65483 cwnd:10 segs_out:1 segs_in:2
"""


def test_parse_ss_reads_acked_bytes_per_socket_and_zero_when_absent():
    assert parse_ss(SS) == {
        "127.0.0.1:8080 127.0.0.1:35494": 100000,  # bytes_acked, not bytes_sent (retransmits)
        "127.0.0.1:8080 127.0.0.1:35500": 0,
    }
    assert parse_ss("") == {}


def test_window_counts_growth_new_sockets_from_zero_and_closed_ones_to_their_last_read():
    samples = [
        {"a": 1000, "b": 50},
        {"a": 1500, "b": 80, "c": 300},  # c opened inside the window
        {"a": 2500, "c": 400},  # b closed after its last read
    ]
    assert bytes_in_window(samples) == 1500 + 30 + 400
    assert bytes_in_window([]) == 0
    assert bytes_in_window([{"a": 7}]) == 0


def test_kilobytes_per_second():
    assert kilobytes_per_s(50_000, 20.0) == 2.5
    assert math.isnan(kilobytes_per_s(10, 0.0))
