"""Every option value of every command under fuzzing (issue 49): a number option takes one of
the shared quantities (cli.options.LIMITS), so it has the same limits in every command; a
value outside them -- NaN, an infinity, a huge or tiny number, a negative, text -- is refused
with exit 2 and a message naming the option, before any work and never with a traceback."""

from __future__ import annotations

import math

import click
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dtsp_mission.cli.main import cli
from dtsp_mission.cli.options import FiniteFloatRange, Quantity

COMMANDS = ("plan", "fly", "sim", "upload", "dubins", "check")
#: Arguments that let a command parse its options (the files need not exist: options fail first).
ARGUMENTS = {"plan": ["t.csv"], "fly": ["m.plan"], "sim": ["--home", "46.8,6.9"],
             "upload": ["m.plan", "--connect", "udpout:127.0.0.1:9"],
             "dubins": ["0,0,0", "100,0,0"], "check": ["t.json"]}


def _command(name: str) -> click.Command:
    return cli.get_command(click.Context(cli), name)


def _number_options():
    """(command, option) for every option of the commands that takes a number."""
    found = []
    for name in COMMANDS:
        for param in _command(name).params:
            if isinstance(param, click.Option) and isinstance(
                    param.type, (Quantity, click.types.FloatParamType, click.types.IntParamType)):
                found.append((name, param))
    return found


def test_every_number_option_takes_a_shared_quantity():
    loose = [f"{name} {param.opts[0]}" for name, param in _number_options()
             if not isinstance(param.type, (Quantity, FiniteFloatRange, click.IntRange))]
    assert loose == []
    # the same option name has the same limits wherever it appears
    limits: dict[str, set] = {}
    for name, param in _number_options():
        if isinstance(param.type, Quantity):
            limits.setdefault(param.opts[0], set()).add(param.type.describe())
    assert {option: spans for option, spans in limits.items() if len(spans) > 1} == {}


QUANTITY_OPTIONS = [(name, param.opts[0], param.type) for name, param in _number_options()
                    if isinstance(param.type, Quantity)]


def outside(quantity: Quantity):
    """Values a quantity refuses: non-numbers, non-finite, beyond either end."""
    high = st.floats(min_value=quantity.high, exclude_min=True, allow_infinity=True,
                     allow_nan=False).filter(lambda v: v > quantity.high)
    low = st.floats(max_value=quantity.low, exclude_max=not quantity.low_open,
                    allow_infinity=True, allow_nan=False).filter(
        lambda v: (v <= quantity.low if quantity.low_open else v < quantity.low)
        and not (quantity.zero and v == 0))
    numbers = st.one_of(high, low).map(lambda v: repr(int(v)) if quantity.integer and math.isfinite(v)
                                       and v == int(v) else repr(v))
    words = st.sampled_from(["nan", "NaN", "inf", "-inf", "1e309", "", "x", "1,5", "0x10"])
    if quantity.integer:
        words = st.one_of(words, st.sampled_from(["1.5", "2e3"]))
    return st.one_of(numbers, words)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_an_option_value_out_of_its_limits_is_refused_naming_the_option(data):
    name, option, quantity = data.draw(st.sampled_from(QUANTITY_OPTIONS))
    value = data.draw(outside(quantity))
    result = CliRunner().invoke(cli, [name, *ARGUMENTS[name], f"{option}={value}"])
    assert result.exit_code == 2, (name, option, value, result.output)
    assert isinstance(result.exception, SystemExit), (name, option, value, result.exception)
    assert option in result.output, result.output


@pytest.mark.parametrize("name,option,quantity", QUANTITY_OPTIONS,
                         ids=[f"{n} {o}" for n, o, _ in QUANTITY_OPTIONS])
def test_an_option_value_within_its_limits_is_taken(name, option, quantity):
    for value in (quantity.low if not quantity.low_open else quantity.low + 1, quantity.high,
                  0 if quantity.zero else quantity.high):
        taken = quantity.convert(str(value), None, None)
        assert taken == value
