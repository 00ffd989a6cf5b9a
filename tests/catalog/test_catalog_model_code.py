"""parse_model_code: what it accepts, what it rejects and how it says so."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fha_studio.catalog import OPTION_ORDER, ModelCode, ModelCodeError, options_allowed, parse_model_code


def test_plain_codes():
    c = parse_model_code("FHA-25C-50-US250")
    assert c == ModelCode("25C", 50, "incremental", "US250", frozenset())
    assert c.supply_voltage == 200 and c.code == "FHA-25C-50-US250"
    c = parse_model_code("FHA-32C-100-S248-B")
    assert (c.frame, c.ratio, c.encoder, c.options, c.has_brake) == ("32C", 100, "absolute", {"B"}, True)


@pytest.mark.parametrize(
    "text",
    [
        "FHA-17C-50-US250-B-L",
        "FHA-17C-50-US250-BL",
        "FHA-17C-50-US250-LB",
        " fha-17c-50-us250-b-l ",
        "FHA-17C-50-US250-L-B",
    ],
)
def test_option_spellings_mean_the_same(text):
    c = parse_model_code(text)
    assert c.options == {"B", "L"}
    assert c.code == "FHA-17C-50-US250-B-L"


def test_f5_and_option_a():
    c = parse_model_code("FHA-17C-160-S248-AF5E")
    assert c.options == {"A", "F5", "E"} and c.supply_voltage == 100
    assert c.code == "FHA-17C-160-S248-A-F5-E"


@pytest.mark.parametrize(
    ("text", "what", "allowed"),
    [
        ("FHA-40C-50-US250-A", "option A", "FHA-17C, FHA-25C, FHA-32C only"),
        ("FHA-25C-50-US250-E", "option E", "FHA-17C only"),
        ("FHA-32C-50-S248-D", "option D", "FHA-17C, FHA-25C only"),
        ("FHA-40C-100-US250-D", "option D", "FHA-17C, FHA-25C only"),
        ("FHA-25C-60-US250", "ratio '60'", "50, 100, 160"),
        ("FHA-25C-1:60-US250", "ratio '1:60'", "50, 100, 160"),
        ("FHA-25C-²-US250", "ratio '²'", "50, 100, 160"),
        ("FHA - 25C-50-US250", "contains a blank", "without blanks"),
        ("FHA-20C-50-US250", "frame '20C'", "17C, 25C, 32C, 40C"),
        ("FHA-25-50-US250", "did you mean 25C", "17C, 25C, 32C, 40C"),
        ("FHA-25C-50-US200", "encoder 'US200'", "US250 (incremental), S248 (absolute)"),
        ("FHA-25C-50-US248", "1-4-2 prints US248", "S248 (absolute)"),
        ("FHA-25C-50-US250-B-B", "option B given twice", "once"),
        ("FHA-25C-50-US250-BB", "option B given twice", "once"),
        ("FHA-25C-50-US250-X", "unknown option 'X'", "A B L C K W D F5 E"),
        ("FHA-25C-50-US250-F", "F5", "A B L C K W D F5 E"),
        ("FHA-25C-50-US250-", "empty option group", "A B L C K W D F5 E"),
        ("FHA-25C-50", "too few parts", "FHA-<frame>-<ratio>-<encoder>"),
        ("FHA25C-50-US250", "missing hyphen", "FHA-<frame>"),
        ("HD-25C-50-US250", "does not start with FHA-", "e.g. FHA-25C-50-US250"),
        ("", "does not start with FHA-", "e.g."),
        ("garbage!", "does not start with FHA-", "e.g."),
    ],
)
def test_rejections_say_what_is_wrong_and_what_is_allowed(text, what, allowed):
    with pytest.raises(ModelCodeError) as info:
        parse_model_code(text)
    message = str(info.value)
    assert what in message and allowed in message
    assert isinstance(info.value, ValueError)
    assert info.value.allowed and info.value.problem


def test_non_string_is_rejected():
    with pytest.raises(ModelCodeError, match="expected a string"):
        parse_model_code(25)  # type: ignore[arg-type]


@st.composite
def valid_codes(draw):
    frame = draw(st.sampled_from(["17C", "25C", "32C", "40C"]))
    ratio = draw(st.sampled_from([50, 100, 160]))
    enc = draw(st.sampled_from(["US250", "S248"]))
    opts = draw(st.lists(st.sampled_from(options_allowed(frame)), unique=True))
    # Split the options into groups: each group is written run together.
    groups, cur = [], []
    for o in opts:
        cur.append(o)
        if draw(st.booleans()):
            groups.append("".join(cur))
            cur = []
    if cur:
        groups.append("".join(cur))
    text = "-".join(["FHA", frame, str(ratio), enc, *groups])
    if draw(st.booleans()):
        text = text.lower()
    return text, (frame, ratio, enc, frozenset(opts))


@settings(max_examples=150, deadline=None)
@given(valid_codes())
def test_any_allowed_code_parses_and_its_canonical_form_round_trips(case):
    text, (frame, ratio, enc, opts) = case
    c = parse_model_code(text)
    assert (c.frame, c.ratio, c.encoder_code, c.options) == (frame, ratio, enc, opts)
    assert parse_model_code(c.code) == c
    assert c.code.split("-")[4:] == [o for o in OPTION_ORDER if o in opts]


@settings(max_examples=200, deadline=None)
@given(
    st.one_of(
        st.text(max_size=30),
        st.lists(st.text(max_size=6), max_size=7).map(lambda parts: "-".join(["FHA", *parts])),
        st.lists(
            st.sampled_from(["17C", "25C", "50", "160", "US250", "S248", "B", "F5", "A", "", "²", "x"]),
            max_size=7,
        ).map(lambda parts: "-".join(["FHA", *parts])),
    )
)
def test_arbitrary_text_parses_or_raises_model_code_error(text):
    try:
        c = parse_model_code(text)
    except ModelCodeError as exc:
        assert "allowed" in str(exc) or "e.g." in str(exc) or "once" in str(exc)
    else:
        assert parse_model_code(c.code) == c
