#!/usr/bin/env python3
"""Unit tests of scripts/check_link_graph.py on small synthetic graphs.

The graphs imitate what `cmake --graphviz` (CMake 3.25) and
cmake/RoverTargetMap.cmake write for this project, and most tests use the
project's real rules file, so they also pin down what link_rules.txt forbids.
Run: python3 tests/architecture/test_check_link_graph.py (or through ctest).
"""

import contextlib
import importlib.util
import io
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CHECKER = os.path.join(ROOT, "scripts", "check_link_graph.py")
RULES = os.path.join(HERE, "link_rules.txt")

# Importing the checker must not leave a __pycache__ in the source tree.
sys.dont_write_bytecode = True
_spec = importlib.util.spec_from_file_location("check_link_graph", CHECKER)
checker = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(checker)

def rule_location(start):
    """Returns 'FILE:LINE' of the real rules file's line starting with `start`."""
    with open(RULES, encoding="utf-8") as stream:
        for number, line in enumerate(stream, 1):
            if line.startswith(start):
                return f"{RULES}:{number}"
    raise AssertionError(f"no '{start}' rule in {RULES}")


EVAL_RULE = rule_location("must-not-reach rover-eval ")
MAPD_RULE = rule_location("must-not-reach mapd ")

# Where today's targets are defined (a subset of the real rover_targets.tsv).
FOLDERS = {
    "rover_warnings": ".",
    "rover_core": "core",
    "rover_ipc": "core/ipc",
    "rover_drivers": "drivers",
    "rover_estimator": "estimator",
    "rover_mapping": "mapping",
    "rover_runtime": "firmware/runtime",
    "rover_roverd": "firmware/roverd",
    "roverd": "firmware/roverd",
    "rover_mapd": "firmware/mapd",
    "mapd": "firmware/mapd",
    "rover_host_eval": "host/eval",
    "rover-eval": "host/eval",
    "rover_sim": "hil/sim",
    "rover-launch": "hil/sim/mission",
    "roverd-sim": "hil/sim/mission",
    "rover_test_support": "tests/support",
    "host_eval_test": "tests/host/eval",
    "fuzz_mcap_reader": "tests/fuzz",
    "bench_eskf": "bench/estimator",
}

# CMake shows these aliases in the real target's label.
ALIASES = {"rover_core": "rover::core", "rover_drivers": "rover::drivers", "rover_estimator": "rover::estimator"}

# A graph that follows the rules: the layering as DESIGN.md wants it, hil
# linking firmware (allowed), tests and benchmarks linking across layers.
CLEAN_EDGES = [
    ("rover_core", "Eigen3::Eigen"),
    ("rover_core", "rover_warnings"),
    ("rover_ipc", "rover_core"),
    ("rover_ipc", "iceoryx_posh::iceoryx_posh"),
    ("iceoryx_posh::iceoryx_posh", "iceoryx_hoofs::iceoryx_hoofs"),
    ("rover_drivers", "rover_core"),
    ("rover_drivers", "PkgConfig::ARAVIS"),
    ("PkgConfig::ARAVIS", "/usr/lib/x86_64-linux-gnu/libaravis-0.8.so"),
    ("rover_drivers", "PkgConfig::GPIOD"),
    ("rover_estimator", "rover_core"),
    ("rover_mapping", "rover_core"),
    ("rover_runtime", "rover_ipc"),
    ("rover_runtime", "PkgConfig::SYSTEMD"),
    ("rover_runtime", "PkgConfig::HTTPLIB"),
    ("PkgConfig::HTTPLIB", "/usr/lib/x86_64-linux-gnu/libcpp-httplib.so"),
    ("rover_roverd", "rover_runtime"),
    ("rover_roverd", "rover_estimator"),
    ("rover_roverd", "rover_drivers"),
    ("roverd", "rover_roverd"),
    ("roverd", "roverd"),
    ("rover_mapd", "rover_mapping"),
    ("rover_mapd", "rover_runtime"),
    ("mapd", "rover_mapd"),
    ("rover_host_eval", "rover_estimator"),
    ("rover_host_eval", "rover_mapping"),
    ("rover_host_eval", "CLI11::CLI11"),
    ("rover-eval", "rover_host_eval"),
    ("rover_sim", "rover_roverd"),
    ("rover_sim", "OpenGL::EGL"),
    ("roverd-sim", "rover_sim"),
    ("rover-launch", "rover_sim"),
    ("host_eval_test", "rover_host_eval"),
    ("host_eval_test", "rover_sim"),
    ("host_eval_test", "rover_test_support"),
    ("fuzz_mcap_reader", "rover_core"),
    ("bench_eskf", "rover_estimator"),
]


def dot_text(edges, aliases=None, alias_nodes=()):
    """Returns a graph in CMake 3.25's graphviz format, legend included.

    `aliases` maps a target to the alias shown in its label; each name in
    `alias_nodes` gets a node of its own instead (as older CMake versions draw
    a link through an alias).
    """
    aliases = ALIASES if aliases is None else aliases
    lines = [
        'digraph "rover" {',
        "node [",
        '  fontsize = "12"',
        "];",
        "subgraph clusterLegend {",
        '  label = "Legend";',
        "  legendNode0 [ label = \"Executable\", shape = egg ];",
        "  legendNode1 [ label = \"Static Library\", shape = octagon ];",
        "  legendNode0 -> legendNode1 [ style = solid ];",
        "}",
    ]
    ids = {}
    for tail, head in edges:
        for name in (tail, head):
            if name not in ids:
                ids[name] = f"node{len(ids)}"
                label = name if name in alias_nodes else name + "".join(
                    f"\\n({alias})" for alias in [aliases.get(name)] if alias)
                lines.append(f'    "{ids[name]}" [ label = "{label}", shape = octagon ];')
        lines.append(f'    "{ids[tail]}" -> "{ids[head]}" [ style = dotted ] // {tail} -> {head}')
    lines.append("}")
    return "\n".join(lines) + "\n"


def with_last_line(dot, line):
    """Returns the graph text `dot` with `line` added just before its closing brace."""
    assert dot.endswith("\n}\n")
    return dot[:-2] + line + "\n}\n"


def tsv_text(folders=None, alias_rows=()):
    """Returns a target map as cmake/RoverTargetMap.cmake writes it."""
    folders = FOLDERS if folders is None else folders
    rows = [f"{name}\t{folder}" for name, folder in folders.items()]
    rows += ["\t".join(row) for row in alias_rows]
    return "\n".join(rows) + "\n"


class CheckerTestCase(unittest.TestCase):
    """Writes the inputs to a temporary folder and runs the checker in-process."""

    def setUp(self):
        """Creates the scratch folder."""
        self._tmp = tempfile.TemporaryDirectory()
        self.dir = self._tmp.name

    def tearDown(self):
        """Removes the scratch folder."""
        self._tmp.cleanup()

    def write(self, name, text):
        """Writes `text` to a scratch file; returns its path."""
        path = os.path.join(self.dir, name)
        with open(path, "w", encoding="utf-8") as stream:
            stream.write(text)
        return path

    def run_checker(self, dot=None, tsv=None, rules=None):
        """Runs main() on the given texts (None: clean graph, real map, real rules).

        Returns (exit status, stdout lines, stderr text).
        """
        dot_path = self.write("graph.dot", dot_text(CLEAN_EDGES) if dot is None else dot)
        tsv_path = self.write("targets.tsv", tsv_text() if tsv is None else tsv)
        rules_path = RULES if rules is None else self.write("rules.txt", rules)
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = checker.main(["--dot", dot_path, "--targets", tsv_path, "--rules", rules_path])
        return status, out.getvalue().splitlines(), err.getvalue()

    def violations_with(self, *extra_edges, **kwargs):
        """Runs the real rules on the clean graph plus `extra_edges`; expects exit 1."""
        status, lines, err = self.run_checker(dot=dot_text(CLEAN_EDGES + list(extra_edges), **kwargs))
        self.assertEqual(status, 1, "\n".join(lines) + err)
        return lines


class LayeringTest(CheckerTestCase):
    """The layer, allow, exempt and shared rules of link_rules.txt, one by one."""

    def test_clean_graph_passes(self):
        """The clean graph (hil -> firmware, tests across layers) has no violation."""
        status, lines, err = self.run_checker()
        self.assertEqual(status, 0, "\n".join(lines) + err)
        self.assertEqual(lines, [f"check_link_graph: link graph follows {RULES}"])

    def test_host_must_not_link_hil(self):
        """Today's rover_host_eval -> rover_sim."""
        lines = self.violations_with(("rover_host_eval", "rover_sim"))
        self.assertIn("host/eval: rover_host_eval -> rover_sim (hil/sim): host must not link hil", lines)

    def test_hil_must_not_link_host(self):
        """Today's rover-launch -> rover_host_eval."""
        lines = self.violations_with(("rover-launch", "rover_host_eval"))
        self.assertEqual(lines,
                         ["hil/sim/mission: rover-launch -> rover_host_eval (host/eval): hil must not link host"])

    def test_host_must_not_link_firmware(self):
        """A host tool linking the runtime."""
        lines = self.violations_with(("rover_host_eval", "rover_runtime"))
        self.assertIn("host/eval: rover_host_eval -> rover_runtime (firmware/runtime): host must not link firmware",
                      lines)

    def test_firmware_must_not_link_hil_or_host(self):
        """Firmware linking the simulator or a host tool library."""
        lines = self.violations_with(("rover_roverd", "rover_sim"), ("rover_mapd", "rover_host_eval"))
        self.assertIn("firmware/roverd: rover_roverd -> rover_sim (hil/sim): firmware must not link hil", lines)
        self.assertIn("firmware/mapd: rover_mapd -> rover_host_eval (host/eval): firmware must not link host", lines)

    def test_layer1_must_not_link_layer2(self):
        """The estimator reaching up into the firmware runtime."""
        lines = self.violations_with(("rover_estimator", "rover_runtime"))
        self.assertIn(
            "estimator: rover_estimator -> rover_runtime (firmware/runtime): estimator must not link firmware", lines)

    def test_layer1_must_not_link_other_layer1(self):
        """Lateral: the estimator linking drivers."""
        lines = self.violations_with(("rover_estimator", "rover_drivers"))
        self.assertIn("estimator: rover_estimator -> rover_drivers (drivers): estimator must not link drivers", lines)

    def test_core_must_not_link_upwards(self):
        """core linking drivers; another core folder linking mapping."""
        lines = self.violations_with(("rover_core", "rover_drivers"), ("rover_ipc", "rover_mapping"))
        self.assertIn("core: rover_core -> rover_drivers (drivers): core must not link drivers", lines)
        self.assertIn("core/ipc: rover_ipc -> rover_mapping (mapping): core must not link mapping", lines)

    def test_layered_target_must_not_link_test_code(self):
        """Exempt folders may link anything, but shipped code must not link them."""
        lines = self.violations_with(("rover_roverd", "rover_test_support"))
        self.assertEqual(
            lines,
            ["firmware/roverd: rover_roverd -> rover_test_support (tests/support): "
             "firmware must not link tests (test and benchmark code)"])

    def test_exempt_folders_link_anything(self):
        """tests/, tests/fuzz and bench/ targets linking every layer pass."""
        edges = CLEAN_EDGES + [("host_eval_test", "rover_runtime"), ("fuzz_mcap_reader", "rover_sim"),
                               ("bench_eskf", "rover_host_eval")]
        status, lines, _ = self.run_checker(dot=dot_text(edges))
        self.assertEqual(status, 0, lines)

    def test_shared_target_must_not_link_project(self):
        """rover_warnings is linked by everyone, so it must link no project target."""
        lines = self.violations_with(("rover_warnings", "rover_core"))
        self.assertEqual(lines,
                         [".: rover_warnings -> rover_core (core): shared target in . must not link project targets"])

    def test_unplaced_folder_is_reported(self):
        """A target in a folder no rule mentions cannot silently escape the layering."""
        folders = dict(FOLDERS, rover_tool="tools/x")
        status, lines, _ = self.run_checker(dot=dot_text(CLEAN_EDGES + [("rover_tool", "rover_sim")]),
                                            tsv=tsv_text(folders))
        self.assertEqual(status, 1)
        self.assertEqual(len(lines), 1)
        self.assertTrue(lines[0].startswith("tools/x: rover_tool: folder is in no layer, exempt or shared rule"), lines)


class ReachTest(CheckerTestCase):
    """The must-not-reach rules: transitive, through any target or library."""

    def test_allowed_by_layering_forbidden_by_reach(self):
        """Today's rover_mapd -> rover_estimator: firmware may link layer 1, mapd may not reach it."""
        lines = self.violations_with(("rover_mapd", "rover_estimator"))
        self.assertEqual(lines, [
            "firmware/mapd: mapd -> rover_mapd (firmware/mapd) -> rover_estimator (estimator): "
            f"mapd must not reach rover_estimator ({MAPD_RULE})"])

    def test_reach_through_static_library_to_external(self):
        """rover-eval -> rover_host_eval -> rover_drivers -> PkgConfig::ARAVIS (layering allows each link)."""
        lines = self.violations_with(("rover_host_eval", "rover_drivers"))
        self.assertIn(
            "host/eval: rover-eval -> rover_host_eval (host/eval) -> rover_drivers (drivers) -> PkgConfig::ARAVIS: "
            f"rover-eval must not reach aravis ({EVAL_RULE})", lines)
        self.assertEqual(len(lines), 2, lines)  # aravis and gpiod, no layering line
        self.assertIn("PkgConfig::GPIOD: rover-eval must not reach gpiod", lines[1])

    def test_host_linking_hil_reaches_everything_forbidden(self):
        """Today's rover_host_eval -> rover_sim brings in iceoryx, httplib, systemd, aravis, gpiod and EGL."""
        lines = self.violations_with(("rover_host_eval", "rover_sim"))
        reached = sorted(line.split(" must not reach ")[1].split(" ")[0] for line in lines if "must not reach" in line)
        self.assertEqual(reached, sorted(["iceoryx", "httplib", "systemd", "aravis", "gpiod", "EGL"]))
        self.assertEqual(len(lines), 7, lines)

    def test_patterns_match_externals_by_substring_ignoring_case(self):
        """'HTTPLIB' finds libcpp-httplib.so; a project target needs its exact name."""
        rules = "layer 0 core\nlayer 1 drivers estimator mapping\nlayer 2 firmware host hil\nshared .\n" \
                "exempt tests bench\nallow hil -> firmware\n" \
                "must-not-reach rover_runtime -> cpp-HTTPLIB rover_ip rover_ipc\n"
        edges = [("rover_runtime", "rover_ipc"),
                 ("rover_runtime", "/usr/lib/x86_64-linux-gnu/libcpp-httplib.so")]
        status, lines, _ = self.run_checker(dot=dot_text(edges), rules=rules)
        self.assertEqual(status, 1)
        self.assertEqual(lines, [
            "firmware/runtime: rover_runtime -> /usr/lib/x86_64-linux-gnu/libcpp-httplib.so: "
            "rover_runtime must not reach cpp-HTTPLIB (" + os.path.join(self.dir, "rules.txt") + ":7)",
            "firmware/runtime: rover_runtime -> rover_ipc (core/ipc): "
            "rover_runtime must not reach rover_ipc (" + os.path.join(self.dir, "rules.txt") + ":7)"])

    def test_rule_for_absent_target_is_a_note(self):
        """A target left out of this configure (optional library missing) is not checked, but said."""
        edges = [(tail, head) for tail, head in CLEAN_EDGES if "rover-eval" not in (tail, head)]
        status, lines, err = self.run_checker(dot=dot_text(edges))
        self.assertEqual(status, 0, lines)
        self.assertIn("rover-eval is not in the link graph; rule not checked", err)


class AliasTest(CheckerTestCase):
    """Aliases resolve to the real target however the graph shows them."""

    def test_aliases_in_labels(self):
        """CMake 3.25 names the aliases in the label: 'rover_estimator\\n(rover::estimator)'."""
        lines = self.violations_with(("rover_core", "rover_drivers"))
        self.assertIn("core: rover_core -> rover_drivers (drivers): core must not link drivers", lines)
        with open(RULES, encoding="utf-8") as stream:
            rules_text = stream.read() + "must-not-reach rover_mapd -> rover::core\n"
        status, lines, _ = self.run_checker(rules=rules_text)
        self.assertEqual(status, 1)
        self.assertEqual(len(lines), 1, lines)
        self.assertIn("rover_mapd -> rover_mapping (mapping) -> rover_core (core): "
                      "rover_mapd must not reach rover::core", lines[0])

    def test_alias_nodes_of_their_own(self):
        """An alias drawn as its own node (older CMake) is merged into the real target."""
        edges = CLEAN_EDGES + [("rover_mapd", "rover::estimator"), ("rover::estimator", "rover_estimator"),
                               ("rover_ipc", "rover::mapping"), ("rover::mapping", "rover_mapping")]
        alias_rows = [("rover::estimator", "estimator", "rover_estimator"),
                      ("rover::mapping", "mapping", "rover_mapping")]
        dot = dot_text(edges, aliases={}, alias_nodes=("rover::estimator", "rover::mapping"))
        status, lines, _ = self.run_checker(dot=dot, tsv=tsv_text(alias_rows=alias_rows))
        self.assertEqual(status, 1)
        self.assertEqual(lines, [
            "core/ipc: rover_ipc -> rover_mapping (mapping): core must not link mapping",
            "firmware/mapd: mapd -> rover_mapd (firmware/mapd) -> rover_estimator (estimator): "
            f"mapd must not reach rover_estimator ({MAPD_RULE})"])


class InputErrorTest(CheckerTestCase):
    """Unreadable or malformed input: exit 2 with the file and line named."""

    def assert_input_error(self, expected, **inputs):
        """Runs the checker; expects exit 2, nothing on stdout and `expected` in stderr."""
        status, lines, err = self.run_checker(**inputs)
        self.assertEqual(status, 2, lines)
        self.assertEqual(lines, [])
        self.assertIn(expected, err)

    def test_missing_file(self):
        """A dot file that does not exist."""
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = checker.main(["--dot", os.path.join(self.dir, "none.dot"), "--targets", RULES, "--rules", RULES])
        self.assertEqual(status, 2)
        self.assertIn("none.dot: cannot read", err.getvalue())

    def test_not_a_graph(self):
        """A file that is no graphviz digraph."""
        self.assert_input_error(os.path.join(self.dir, "graph.dot") + ":1: expected 'digraph NAME {'",
                                dot="rover_core\trover\n")

    def test_truncated_graph(self):
        """The closing brace is missing."""
        text = dot_text(CLEAN_EDGES).rstrip("}\n") + "\n"
        self.assert_input_error("graph not closed by '}'", dot=text)

    def test_edge_to_undeclared_node(self):
        """An edge naming a node that was never declared; the line number is reported."""
        text = with_last_line(dot_text(CLEAN_EDGES), '    "node1" -> "node999"')
        line = len(text.splitlines()) - 1
        self.assert_input_error(f"graph.dot:{line}: edge uses undeclared node node999", dot=text)

    def test_garbled_edge(self):
        """A line with an arrow that is no edge statement."""
        text = with_last_line(dot_text(CLEAN_EDGES), '    "node1" -> ')
        self.assert_input_error("cannot parse edge", dot=text)

    def test_tsv_with_one_column(self):
        """A target map line without a folder."""
        self.assert_input_error("targets.tsv:2: expected 'target<TAB>folder", tsv="rover_core\tcore\nrover_drivers\n")

    def test_tsv_of_another_build(self):
        """No target of the map appears in the graph."""
        self.assert_input_error("none of its targets is in", tsv="other\tcore\n")

    def test_rules_unknown_directive(self):
        """A typo in the rules file."""
        self.assert_input_error("rules.txt:2: unknown directive 'layr'", rules="layer 0 core\nlayr 1 drivers\n")

    def test_rules_bad_layer(self):
        """A layer without a number."""
        self.assert_input_error("rules.txt:1: expected 'layer N FOLDER...'", rules="layer core\n")

    def test_rules_folder_placed_twice(self):
        """One folder in two places."""
        self.assert_input_error("rules.txt:2: folder 'core' already placed on line 1",
                                rules="layer 0 core\nexempt core/\n")

    def test_rules_allow_outside_layers(self):
        """An exception naming a folder that has no layer."""
        self.assert_input_error("allow hil -> tests: 'tests' is not in any layer",
                                rules="layer 0 core\nlayer 1 hil\nexempt tests\nallow hil -> tests\n")


class CommandLineTest(unittest.TestCase):
    """The script as ctest and people run it."""

    def run_script(self, *args):
        """Runs the checker as a program; returns the CompletedProcess."""
        return subprocess.run([sys.executable, CHECKER, *args], capture_output=True, text=True, check=False,
                              env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))

    def test_help_explains_the_rules_format(self):
        """--help documents every directive and the exit status."""
        result = self.run_script("--help")
        self.assertEqual(result.returncode, 0)
        for word in ("--dot", "--targets", "--rules", "layer N", "allow", "exempt", "shared", "must-not-reach",
                     "exit status"):
            self.assertIn(word, result.stdout)

    def test_exit_status_of_the_program(self):
        """1 on a violation, 2 without arguments."""
        with tempfile.TemporaryDirectory() as folder:
            dot = os.path.join(folder, "g.dot")
            tsv = os.path.join(folder, "t.tsv")
            with open(dot, "w", encoding="utf-8") as stream:
                stream.write(dot_text(CLEAN_EDGES + [("rover-launch", "rover_host_eval")]))
            with open(tsv, "w", encoding="utf-8") as stream:
                stream.write(tsv_text())
            result = self.run_script("--dot", dot, "--targets", tsv, "--rules", RULES)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("hil must not link host", result.stdout)
        self.assertEqual(self.run_script().returncode, 2)

    def test_real_rules_file(self):
        """link_rules.txt parses, and holds the layering and the two reach rules."""
        rules = checker.parse_rules(RULES)
        self.assertEqual({folder: entry.level for folder, entry in rules.entries.items() if entry.kind == "layer"},
                         {"core": 0, "drivers": 1, "estimator": 1, "mapping": 1, "firmware": 2, "host": 2, "hil": 2})
        self.assertEqual(rules.allowed, {("hil", "firmware")})
        self.assertEqual([(rule.target, rule.patterns) for rule in rules.reach],
                         [("rover-eval", ["iceoryx", "httplib", "systemd", "aravis", "gpiod", "EGL"]),
                          ("mapd", ["rover_estimator"])])


if __name__ == "__main__":
    unittest.main()
