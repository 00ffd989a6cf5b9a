"""The CN3 codec: framing, round trips, and resynchronisation under arbitrary bytes."""

from __future__ import annotations

import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fha_studio import paths
from fha_studio.hardware import protocol as p
from fha_studio.hardware.protocol import (
    Command,
    Garbage,
    Reply,
    Request,
    Status,
    StreamDecoder,
    UnknownRequest,
    decode_reply,
    decode_request,
)

FUZZ = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])

requests = st.builds(Request, st.sampled_from(list(Command)), st.integers(p.VALUE_MINIMUM, p.VALUE_MAXIMUM))
data_lines = st.text(
    alphabet=st.characters(min_codepoint=0x20, max_codepoint=0x7E), min_size=1, max_size=40
).filter(lambda s: s not in ("q", "s", "x"))
replies = st.builds(Reply, st.lists(data_lines, max_size=5).map(tuple), st.sampled_from(list(Status)))


def feed_all(decode, chunks):
    """Messages out of a stream fed in the given chunks (the caller-owns-the-buffer loop)."""
    decoder = StreamDecoder(decode)
    out = []
    for chunk in chunks:
        out += decoder.feed(chunk)
    return out, decoder.pending


def without_garbage(messages):
    return [m for m in messages if not isinstance(m, Garbage)]


# --- the documented frames, byte for byte (HA-655 manual p.20-21) -----------------------------


def test_documented_frames_byte_for_byte():
    assert Request(Command.DGR).encode() == b"DGR+00000\r"
    assert Request(Command.OWW).encode() == b"OWW+00000\r"
    assert Request(Command.MOV, -4500).encode() == b"MOV-04500\r"
    assert len(Request(Command.JOG, 99999).encode()) == p.FRAME_LENGTH
    assert decode_reply(b"-123456\rq\r") == (10, Reply(("-123456",), Status.DONE))
    assert decode_reply(b"q\r") == (2, Reply((), Status.DONE))
    assert decode_reply(b"s\r") == (2, Reply((), Status.SERVO_ON))
    assert decode_reply(b"x\r") == (2, Reply((), Status.REJECTED))


def test_minus_zero_reads_as_zero():
    assert decode_request(b"DGR-00000\r") == (10, Request(Command.DGR, 0))


def test_drive_waits_for_all_ten_characters():
    frame = b"DGR+00000\r"
    for n in range(len(frame)):
        assert decode_request(frame[:n]) == (0, None)


def test_unknown_command_is_a_frame_the_drive_rejects():
    assert decode_request(b"ZZZ+00012\r") == (10, UnknownRequest("ZZZ", 12))


@pytest.mark.parametrize("bad", [b"dgr+00000\r", b"DGR 00000\r", b"DGR+0000A\r", b"DGR+00000\n"])
def test_malformed_frames_are_garbage(bad):
    messages, _ = feed_all(decode_request, [bad + b"IOS+00000\r"])
    assert without_garbage(messages) == [Request(Command.IOS)]
    assert b"".join(m.data for m in messages if isinstance(m, Garbage)) == bad


def test_request_value_range_is_checked_on_encode():
    with pytest.raises(ValueError, match="outside"):
        Request(Command.MOV, 100000)
    with pytest.raises(ValueError, match="integer"):
        Request(Command.MOV, 1.5)


def test_reply_data_lines_are_checked_on_encode():
    for bad in ("", "q", "a\rb", "é", "x" * (p.MAX_LINE_CHARS + 1)):
        with pytest.raises(ValueError, match="data line"):
            Reply((bad,)).encode()


# --- resynchronisation -----------------------------------------------------------------------


def test_half_frame_then_good_frame_loses_only_the_half():
    messages, pending = feed_all(decode_request, [b"DGR+00", b"OWW+00000\r"])
    assert without_garbage(messages) == [Request(Command.OWW)]
    assert messages[0] == Garbage(b"DGR+00", "bytes before a request frame")
    assert pending == b""


def test_reply_after_noise_and_stray_crs():
    messages, _ = feed_all(decode_reply, [b"\x00\xff\r\n12\rq\r"])
    assert messages[-1] == Reply(("12",), Status.DONE)
    assert not messages[0].printable


def test_noise_inside_a_reply_marks_it_corrupt():
    _, reply = decode_reply(b"1\x002\rq\r")
    assert reply == Reply(("12",), Status.DONE, corrupt=True)
    _, reply = decode_reply(b"12\r\rq\r")  # an empty line is not something a drive sends
    assert reply.corrupt


def test_overlong_line_ends_the_reply_as_garbage():
    used, message = decode_reply(b"1" * (p.MAX_LINE_CHARS + 1))
    assert used == p.MAX_LINE_CHARS + 1 and isinstance(message, Garbage)


def test_reply_lines_accumulate_until_the_terminal():
    buf = b"HA-655-2-200\rFHA-17C-50-US250\rsim 1.0\r"
    assert decode_reply(buf) == (0, None)
    assert decode_reply(buf + b"q\r")[1] == Reply(("HA-655-2-200", "FHA-17C-50-US250", "sim 1.0"))


# --- round trips and fuzzing ------------------------------------------------------------------


@FUZZ
@given(requests)
def test_every_request_round_trips(request):
    data = request.encode()
    assert re.fullmatch(rb"[A-Z]{3}[+-][0-9]{5}\r", data)
    assert decode_request(data) == (p.FRAME_LENGTH, request)


@FUZZ
@given(replies)
def test_every_reply_round_trips(reply):
    data = reply.encode()
    assert decode_reply(data) == (len(data), reply)


@FUZZ
@given(st.lists(requests, min_size=1, max_size=5), st.data())
def test_requests_split_anywhere_decode_the_same(reqs, data):
    stream = b"".join(r.encode() for r in reqs)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=6)))
    chunks = [stream[a:b] for a, b in zip([0, *cuts], [*cuts, len(stream)], strict=True)]
    assert feed_all(decode_request, chunks) == (reqs, b"")
    assert feed_all(decode_request, [bytes([b]) for b in stream]) == (reqs, b"")


@FUZZ
@given(st.lists(replies, min_size=1, max_size=4), st.data())
def test_replies_split_anywhere_decode_the_same(reps, data):
    stream = b"".join(r.encode() for r in reps)
    cut = data.draw(st.integers(0, len(stream)))
    assert feed_all(decode_reply, [stream[:cut], stream[cut:]]) == (reps, b"")
    assert feed_all(decode_reply, [bytes([b]) for b in stream]) == (reps, b"")


@FUZZ
@given(st.binary(max_size=200))
def test_decoders_never_raise_and_always_progress(junk):
    for decode in (decode_request, decode_reply):
        buf = bytearray(junk)
        while True:
            used, message = decode(buf)
            assert 0 <= used <= len(buf)
            if used == 0:
                assert message is None
                break
            del buf[:used]
        assert len(buf) < max(p.FRAME_LENGTH, p.MAX_LINE_CHARS + 1)


@FUZZ
@given(st.binary(max_size=60), requests)
def test_request_decoder_resyncs_on_the_next_good_frame(junk, request):
    # Garbage, then a good frame: the frame comes out (the garbage may itself hold frames).
    messages, pending = feed_all(decode_request, [junk, request.encode()])
    assert pending == b""
    assert without_garbage(messages)[-1] == request


@FUZZ
@given(st.binary(max_size=60).filter(lambda b: b"\r" not in b), replies)
def test_reply_decoder_resyncs_after_a_cr(junk, reply):
    # Noise without CR, a CR (the end of whatever line it was), then a good reply: after at most
    # one spoiled reply the good one comes out whole.
    messages, pending = feed_all(decode_reply, [junk + b"\r", reply.encode()])
    assert pending == b""
    good = [m for m in messages if isinstance(m, Reply)]
    # the spoiled line either is dropped, ends as a spurious terminal, or leads the real lines
    assert good[-1].status == reply.status
    assert good[-1].lines[len(good[-1].lines) - len(reply.lines):] == reply.lines
    # and a second good reply after that always comes out exactly
    messages, _ = feed_all(decode_reply, [junk + b"\r", reply.encode(), reply.encode()])
    assert [m for m in messages if isinstance(m, Reply)][-1] == reply


@FUZZ
@given(requests, st.integers(0, 9), st.binary(min_size=1, max_size=1))
def test_corrupted_frame_never_decodes_as_another_valid_frame_silently(request, pos, byte):
    frame = bytearray(request.encode())
    frame[pos] = byte[0]
    messages, _ = feed_all(decode_request, [bytes(frame), Request(Command.STP).encode()])
    good = without_garbage(messages)
    assert good[-1] == Request(Command.STP)
    for m in good[:-1]:  # a corrupted byte can only turn into another well-formed frame
        assert m == p.decode_request(bytes(frame))[1]


# --- docs/protocol.md lists exactly the codec's commands -------------------------------------


def test_protocol_doc_table_lists_every_command():
    doc = (paths.resources_dir().parent / "docs" / "protocol.md").read_text()
    table = set(re.findall(r"^\| `([A-Z]{3})` \|", doc, flags=re.M))
    assert table == {c.value for c in Command}


def test_value_formats():
    assert p.format_values([12, -3, 0]) == "12,-3,0"
    assert p.parse_values("12,-3,0") == [12, -3, 0]
    with pytest.raises(ValueError, match="comma-separated"):
        p.parse_values("1,,2")
    assert p.parse_int("-123") == -123
    with pytest.raises(ValueError, match="signed integer"):
        p.parse_int("12a")
    assert p.split_absolute_position(p.join_absolute_position(-3, 100)) == (-3, 100)
    assert p.character_time_s() == pytest.approx(1 / 1920)


def test_protocol_doc_examples_are_what_the_codec_says():
    doc = (paths.resources_dir().parent / "docs" / "protocol.md").read_text()
    examples = doc[doc.index("## Examples, byte by byte") : doc.index("## Transports")]
    hex_lines = re.findall(r"^([<>]) ((?:[0-9A-F]{2} )+)\s*(\S.*)?$", examples, flags=re.M)
    assert len(hex_lines) > 20
    for direction, hexes, _text in hex_lines:
        data = bytes.fromhex(hexes)
        if direction == ">" and len(data) == p.FRAME_LENGTH:
            used, request = decode_request(data)
            assert used == p.FRAME_LENGTH and isinstance(request, Request | UnknownRequest), data
            assert encode_or_none(request) in (data, None)
        elif direction == "<":
            messages, pending = feed_all(decode_reply, [data])
            assert pending == b"" and isinstance(messages[-1], Reply), data
            if data.startswith(b"5\xff"):
                assert messages[-1].corrupt


def test_protocol_doc_packed_block_example_is_what_the_codec_says():
    """The TRP example of docs/protocol.md: its bytes decode to the values the text states, and
    encoding those values gives exactly its bytes."""
    doc = (paths.resources_dir().parent / "docs" / "protocol.md").read_text()
    examples = doc[doc.index("## Examples, byte by byte") : doc.index("## Transports")]
    start = examples.index("A packed trace block")
    block = examples[start : examples.index("```", examples.index("```", start) + 3)]
    text_rows = re.search(r"a capture of 3 samples\s+\(([-0-9, ()]+)\)\.", block).group(1)
    pairs = re.findall(r"\(?([-0-9]+, [-0-9]+)\)?", text_rows)
    rows = [tuple(int(v) for v in pair.split(",")) for pair in pairs]
    assert rows == [(1000, 0), (1010, -150), (1025, -300)]
    (request_hex,) = re.findall(r"^> ((?:[0-9A-F]{2} )+)", block, flags=re.M)
    (reply_hex,) = re.findall(r"^< ((?:[0-9A-F]{2} )+)", block, flags=re.M)
    used, request = decode_request(bytes.fromhex(request_hex))
    assert used == p.FRAME_LENGTH and request == Request(Command.TRP, 0)
    messages, pending = feed_all(decode_reply, [bytes.fromhex(reply_hex)])
    reply = messages[-1]
    assert pending == b"" and isinstance(reply, Reply) and not reply.corrupt
    assert p.decode_packed_block(reply.lines, 3, 2) == rows
    assert Reply(tuple(p.encode_packed_block(rows))).encode() == bytes.fromhex(reply_hex)
    check = int(re.search(r"Check (\d+) = ", block).group(1))
    assert p.packed_check(reply.lines[0][:-2]) == check


def encode_or_none(request):
    return request.encode() if isinstance(request, Request) else None


# --- the packed trace block (TRP) ------------------------------------------------------------

_blocks = st.integers(1, p.TRACE_MAX_CHANNELS).flatmap(
    lambda c: st.lists(st.tuples(*[st.integers(-(2**31), 2**31 - 1)] * c), min_size=1,
                       max_size=p.TRACE_BLOCK_SAMPLES))


@given(_blocks)
@settings(max_examples=200, suppress_health_check=[HealthCheck.too_slow])
def test_packed_block_round_trips_in_printable_lines_that_are_never_a_terminal(rows):
    lines = p.encode_packed_block(rows)
    assert p.decode_packed_block(lines, len(rows), len(rows[0])) == rows
    for line in lines:
        assert 2 <= len(line) <= p.PACKED_LINE_CHARS and set(line) <= set(p.PACKED_ALPHABET)
    # through the reply codec: the lines come back as one reply, not cut short by a terminal
    messages, pending = feed_all(decode_reply, [Reply(tuple(lines)).encode()])
    assert pending == b"" and messages == [Reply(tuple(lines))]


def test_packed_block_refuses_a_changed_character_a_short_block_and_a_foreign_character():
    rows = [(100 * i, -7 * i, 3, 12345678) for i in range(64)]
    (line, *rest) = p.encode_packed_block(rows)
    for k in range(len(line) - 2):  # every single substitution in the first line is seen
        v = p.PACKED_ALPHABET.index(line[k])
        changed = line[:k] + p.PACKED_ALPHABET[(v + 1) % 64] + line[k + 1:]
        with pytest.raises(ValueError, match="check"):
            p.decode_packed_block([changed, *rest], 64, 4)
    with pytest.raises(ValueError, match="expected 63 samples x 4 channels"):
        p.decode_packed_block([line, *rest], 63, 4)
    with pytest.raises(ValueError, match="alphabet"):
        p.decode_packed_block(["A,B" + line[3:], *rest], 64, 4)


def test_packed_block_of_slow_signals_is_about_one_character_per_value():
    rows = [(1000 + 2 * i, 5000, i % 3, 0) for i in range(64)]
    chars = sum(len(line) for line in p.encode_packed_block(rows))
    assert chars <= 64 * 4 + 8


def test_the_dgr_count_per_motor_turn_is_the_catalogues_absolute_encoder():
    from fha_studio.catalog import tables

    assert tables.encoder_resolution_table("absolute").counts_per_motor_rev == p.ABSOLUTE_COUNTS_PER_TURN


def test_every_command_has_words_for_a_person():
    from fha_studio.hardware.protocol import COMMAND_WORDS, command_words

    assert set(COMMAND_WORDS) == set(p.Command)
    assert command_words(p.Command.PSL, 8) == "select parameter-mode item 8"
    assert command_words(p.Command.MOV, 1000) == "move by an angle"  # a value that names nothing
