"""Transports: pyserial URLs, the guarded port, the in-process pipe pair."""

from __future__ import annotations

import errno
import os
import socket
import threading
import time

import pytest
import serial

from fha_studio.hardware.errors import LinkLost
from fha_studio.hardware.transport import (
    SIM_HANDLER_PACKAGE,
    corrupt_at,
    open_transport,
    pipe_pair,
    port_failure_words,
    register_url_handlers,
    split_every,
)


def test_loop_url_echoes_at_cn3_settings():
    port = open_transport("loop://", timeout=0.2)
    try:
        assert (port.baudrate, port.bytesize, port.parity, port.stopbits) == (19200, 8, "N", 1)
        port.write(b"DGR+00000\r")
        assert port.read(10) == b"DGR+00000\r"
    finally:
        port.close()


def test_sim_scheme_is_registered():
    register_url_handlers()
    register_url_handlers()
    assert serial.protocol_handler_packages.count(SIM_HANDLER_PACKAGE) == 1


def test_unknown_scheme_is_a_clear_value_error():
    with pytest.raises(ValueError, match="unknown URL scheme 'nope'"):
        open_transport("nope://x")


def test_missing_device_is_link_lost_naming_it():
    with pytest.raises(LinkLost, match="/dev/ttyNOPE0") as info:
        open_transport("/dev/ttyNOPE0")
    assert info.value.port == "/dev/ttyNOPE0"
    # once, in words: not pyserial's "[Errno 2] could not open port X: [Errno 2] No such file ..."
    assert str(info.value) == ("cannot open /dev/ttyNOPE0: no such port (is the USB-serial adapter "
                               "plugged in, and is this its name?)")


def test_a_socket_nothing_listens_on_is_said_in_words():
    with socket.socket() as bound:  # bound, not listening (held: nobody else can take the port)
        bound.bind(("127.0.0.1", 0))
        port = bound.getsockname()[1]
        with pytest.raises(LinkLost) as info:
            open_transport(f"socket://127.0.0.1:{port}")
    assert str(info.value) == (f"cannot open socket://127.0.0.1:{port}: nothing accepts connections there "
                               "(connection refused: is the server running, and is this its port?)")


@pytest.mark.parametrize(("error", "words"), [
    (serial.SerialException(errno.EACCES, "could not open port /dev/ttyS0: [Errno 13] Permission denied"),
     "permission denied (on Linux: add the user to the dialout group and log in again)"),
    (serial.SerialException(errno.EBUSY, "could not open port /dev/ttyUSB0: [Errno 16] busy"),
     "the port is in use by another program"),
    (serial.SerialException("could not open port 'COM3': PermissionError(13, 'Access is denied.', None, 5)"),
     "access denied: the port is in use by another program"),
    (serial.SerialException("could not open port 'COM9': FileNotFoundError(2, 'The system cannot find')"),
     "no such port (is the USB-serial adapter plugged in, and is this its name?)"),
    (serial.SerialException("something else"), "something else"),
])
def test_a_port_that_does_not_open_is_said_in_words(error, words):
    assert port_failure_words(error) == words


def test_pty_whose_other_side_closes_is_link_lost():
    master, slave = os.openpty()
    path = os.ttyname(slave)
    port = open_transport(path, timeout=0.5)
    try:
        os.write(master, b"q\r")
        assert port.read(2) == b"q\r"
        os.close(master)
        with pytest.raises(LinkLost, match=path):
            port.read(1)
    finally:
        port.close()
        os.close(slave)


def test_socket_with_an_open_timeout_talks_and_closes_at_once(time_ceiling):
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    try:
        port = open_transport(f"socket://127.0.0.1:{server.getsockname()[1]}", timeout=0.5,
                              open_timeout_s=2.0)
        peer, _ = server.accept()
        with peer:
            port.write(b"DGR\r")
            assert peer.recv(16) == b"DGR\r"
            peer.sendall(b"DGR+00000\r")
            assert port.read(10) == b"DGR+00000\r"
            started = time.monotonic()
            port.close()  # without pyserial's 0.3 s pause for a reconnect
            time_ceiling("closing a bounded socket port", time.monotonic() - started, 0.25)
            assert not port.is_open
    finally:
        server.close()


def test_socket_connect_that_nothing_accepts_gives_up_at_the_open_timeout(time_ceiling):
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(0)
    address = server.getsockname()
    filler = socket.create_connection(address, timeout=5)  # the backlog's one place
    try:
        started = time.monotonic()
        with pytest.raises(LinkLost, match=r"nothing accepted the connection in 0\.5 s") as caught:
            open_transport(f"socket://127.0.0.1:{address[1]}", open_timeout_s=0.5)
        assert "\n" not in str(caught.value)
        taken = time.monotonic() - started
        assert taken >= 0.45, "gave up before its time: the backlog took the connection?"
        time_ceiling("a socket connect bounded at 0.5 s", taken, 5.0)
    finally:
        filler.close()
        server.close()


def test_pipe_carries_bytes_and_times_out():
    host, drive = pipe_pair()
    host.timeout = drive.timeout = 0.05
    host.write(b"abc")
    assert drive.in_waiting == 3
    assert drive.read(5) == b"abc"  # fewer than asked: the timeout passed
    assert drive.read(1) == b""
    assert host.written == b"abc"


def test_pipe_write_filters_split_and_corrupt():
    host, drive = pipe_pair()
    drive.timeout = 0
    chunks = []
    host.write_filter = lambda data: chunks.extend(split_every(2)(data)) or split_every(2)(data)
    host.write(b"12345")
    assert chunks == [b"12", b"34", b"5"]
    assert drive.read(5) == b"12345"
    host.write_filter = corrupt_at(1, 0xFF)
    host.write(b"abc")
    assert drive.read(3) == b"a\xffc"


def test_pipe_read_wakes_when_data_arrives():
    host, drive = pipe_pair()
    drive.timeout = 5
    got = []
    reader = threading.Thread(target=lambda: got.append(drive.read(2)))
    reader.start()
    host.write(b"q\r")
    reader.join(timeout=5)
    assert got == [b"q\r"]


def test_pipe_unplug_and_peer_close_raise_serial_exceptions():
    host, drive = pipe_pair()
    drive.close()
    host.timeout = 1
    with pytest.raises(serial.SerialException, match="other end"):
        host.write(b"x")
    with pytest.raises(serial.SerialException, match="other end closed"):
        host.read(1)
    host2, drive2 = pipe_pair()
    host2.unplug()
    with pytest.raises(serial.SerialException, match="disconnected"):
        drive2.read(1)
