"""The command line, run as a user runs it (a real process through the console script)."""

import json
import subprocess
import sys
import textwrap

import numpy as np

from conftest import environment_with_distribution
from dtsp_mission.tour import tour_through_poses, tour_to_dict, write_tour


def run(*arguments, env=None):
    return subprocess.run([sys.executable, "-m", "dtsp_mission.cli", *arguments],
                          capture_output=True, text=True, env=env, timeout=300)


def test_dubins_command_prints_the_exact_path():
    result = run("dubins", "0,0,0", "0,0,180", "--radius", "80")
    assert result.returncode == 0, result.stderr
    assert "word RLR" in result.stdout and "(7.330383 rho)" in result.stdout


def test_dubins_command_rejects_bad_radius_with_exit_2():
    result = run("dubins", "0,0,0", "10,0,0", "--radius", "0")
    assert result.returncode == 2
    assert "--radius" in result.stderr and "from 0.1 to 20000 m" in result.stderr


def test_check_command_on_valid_and_broken_tours(tmp_path, rng):
    tour = tour_through_poses(rng.uniform(0, 1000, (10, 2)), np.arange(10), np.zeros(10), 50.0)
    good = write_tour(tour, tmp_path / "good.json")
    result = run("check", str(good))
    assert result.returncode == 0 and result.stdout.startswith("valid")
    data = tour_to_dict(tour)
    data["segments"][2]["x_m"] += 1.0
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    result = run("check", str(bad))
    assert result.returncode == 1 and "INVALID" in result.stdout and "C1" in result.stdout
    result = run("check", str(tmp_path / "missing.json"))
    assert result.returncode == 2 and "no such file" in result.stderr


def test_a_broken_plugin_is_reported_and_the_cli_still_works(tmp_path):
    """A distribution on the path whose command entry point cannot be imported."""
    env = environment_with_distribution(tmp_path, "broken-plugin", textwrap.dedent("""\
        [dtsp_mission.commands]
        exploding = no_such_module_anywhere:command
        """))
    listing = run("--help", env=env)
    assert listing.returncode == 0
    assert "exploding" in listing.stdout and "broken plugin" in listing.stdout
    assert "dubins" in listing.stdout
    works = run("dubins", "0,0,0", "100,0,0", "--radius", "10", env=env)
    assert works.returncode == 0 and "word LSL" in works.stdout
    broken = run("exploding", env=env)
    assert broken.returncode != 0 and "could not be loaded" in broken.stderr


def test_every_command_has_help_with_an_example():
    """The user guide promises it: every command and subcommand shows an example in --help."""
    import click
    from click.testing import CliRunner

    from dtsp_mission.cli.main import cli

    def commands(group, path):
        for name, command in group.commands.items():
            yield [*path, name]
            if isinstance(command, click.Group):
                yield from commands(command, [*path, name])

    missing = [" ".join(path) for path in commands(cli, [])
               if "Example" not in CliRunner().invoke(cli, [*path, "--help"]).output]
    assert not missing, f"no example in --help of: {missing}"


def test_no_command_module_imports_another():
    """Commands share code through cli.options and cli.runs, never through each other."""
    import ast
    from pathlib import Path
    folder = Path(__file__).resolve().parents[2] / "dtsp_mission" / "cli"
    commands = {p.stem for p in folder.glob("*_command.py")}
    for path in folder.glob("*_command.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                imported = (node.module or "").split(".")[-1]
                assert imported not in commands, f"{path.name} imports {node.module}"


def test_the_library_speaks_in_its_own_terms_and_the_cli_in_options():
    """No message of the library names a command-line option (an API caller never passes
    one); it names its parameters in backticks, and the CLI prints the option that sets
    each (every such name in the library is mapped)."""
    import ast
    import re
    from pathlib import Path
    from dtsp_mission.cli.console import OPTIONS, in_cli_terms
    package = Path(__file__).resolve().parents[2] / "dtsp_mission"
    named, flags = set(), []
    for path in package.rglob("*.py"):
        # the CLI itself; the benchmarks; the SITL driver, which starts other programs with
        # their own command-line options
        if "cli" in path.relative_to(package).parts or path.parent.name in ("bench", "sitl"):
            continue
        tree = ast.parse(path.read_text())
        docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                      if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef))
                      and node.body and isinstance(node.body[0], ast.Expr)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                    and id(node) not in docstrings:
                flags += [f"{path.name}: {m}" for m in re.findall(r"(?<![\w-])--[a-z][a-z-]+", node.value)]
                named |= set(re.findall(r"`([a-z_]+(?:=False)?)`", node.value))
    assert not flags, flags
    assert named and named <= set(OPTIONS), named - set(OPTIONS)
    assert in_cli_terms("lower `max_items` and plan again (`verify=False`)") == \
        "lower --max-items and plan again (--no-verify)"
