#!/usr/bin/env python3
"""Checks the project's link graph against its layering rules.

Reads the graph that `cmake --graphviz=FILE.dot` writes, the target -> folder
map that cmake/RoverTargetMap.cmake writes (rover_targets.tsv in the build
folder) and a rules file (tests/architecture/link_rules.txt), and prints one
line per forbidden link.

Exit status: 0 clean, 1 violations found, 2 unreadable input or bad usage.
"""

import argparse
import collections
import re
import sys

RULES_HELP = """\
rules file: one directive per line, '#' starts a comment.

  layer N FOLDER...          FOLDERs are layer N (0 is the bottom). A target in
                             a layered folder may link targets of its own
                             folder and of lower layers, nothing else.
  allow FOLDER -> FOLDER     the first folder may also link the second one
                             (an exception for two folders of one layer).
  exempt FOLDER...           targets here may link anything (tests, benchmarks);
                             no layered target may link them.
  shared FOLDER...           targets here (build settings such as
                             rover_warnings, defined in the root ".") may be
                             linked by any target; they link no project target.
  must-not-reach TARGET -> PATTERN...
                             TARGET must not reach any PATTERN through the link
                             graph, directly or transitively. A PATTERN that
                             names a project target (or its alias) matches that
                             target only; any other PATTERN matches external
                             libraries whose name contains it, ignoring case
                             ("httplib" matches PkgConfig::HTTPLIB and
                             /usr/lib/x86_64-linux-gnu/libcpp-httplib.so).

A target's folder is the source folder that defines it, relative to the project
root. A FOLDER entry covers that folder and everything below it; the longest
entry wins (so "exempt hil/scenarios" would carve a part out of "layer 2 hil").
"." covers only the root folder itself. Every project target must fall under some
entry, so a new top-level folder has to be placed in the rules.
"""


class InputError(Exception):
    """An input file that cannot be read or parsed; exit status 2."""

    def __init__(self, path, line, message):
        """Remembers where the problem is: `line` is 1-based, or 0 for the whole file."""
        where = f"{path}:{line}" if line else path
        super().__init__(f"{where}: {message}")


Rules = collections.namedtuple("Rules", "entries allowed reach path")
# kind: "layer", "exempt" or "shared"; level: the layer number (None otherwise).
Entry = collections.namedtuple("Entry", "kind level line")
ReachRule = collections.namedtuple("ReachRule", "target patterns line")


def read_lines(path):
    """Returns the lines of `path`, raising InputError when it cannot be read."""
    try:
        with open(path, encoding="utf-8") as stream:
            return stream.read().splitlines()
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(path, 0, f"cannot read: {error}") from error


# --- graphviz ----------------------------------------------------------------

_ID = r'(?:"(?:[^"\\]|\\.)*"|[A-Za-z_][A-Za-z0-9_]*)'
_NODE = re.compile(r"^\s*(" + _ID + r")\s*\[(.*)\]\s*;?\s*(?://.*)?$")
_EDGE = re.compile(r"^\s*(" + _ID + r")\s*->\s*(" + _ID + r")\s*(?:\[.*\])?\s*;?\s*(?://.*)?$")
_LABEL = re.compile(r'\blabel\s*=\s*"((?:[^"\\]|\\.)*)"')


def _unquote(token):
    """Returns a dot ID without its quotes and escapes."""
    if token.startswith('"'):
        return re.sub(r'\\(["\\])', r"\1", token[1:-1])
    return token


def _strip_comment(line):
    """Returns `line` without a trailing // comment (a // inside quotes stays)."""
    quoted = False
    for index, char in enumerate(line):
        if char == '"' and (index == 0 or line[index - 1] != "\\"):
            quoted = not quoted
        elif not quoted and line.startswith("//", index):
            return line[:index]
    return line


def _label_names(label):
    """Splits a CMake node label into the target name and its aliases.

    CMake 3.25 writes an aliased target as "rover_core\\n(rover::core)": the real
    name, then one "(alias)" line per alias.
    """
    lines = label.split("\\n")
    aliases = [line[1:-1] for line in lines[1:] if line.startswith("(") and line.endswith(")")]
    return _unquote('"' + lines[0] + '"'), aliases


def parse_dot(path):
    """Reads a CMake graphviz file into ({node id: (name, aliases)}, [(id, id)]).

    Only the subset CMake writes is understood: node statements with a label,
    edge statements, attribute blocks; the legend cluster is skipped. A line
    that looks like a node or an edge but does not parse, or an edge between
    undeclared nodes, is an InputError, so a truncated file is not mistaken
    for a clean graph.
    """
    lines = read_lines(path)
    nodes, edges = {}, []
    depth, legend_depth, seen_digraph, closed = 0, None, False, False
    for number, line in enumerate(lines, 1):
        text = _strip_comment(line).strip()
        if not text:
            continue
        if not seen_digraph:
            if not re.match(r"^(strict\s+)?digraph\b.*\{$", text):
                raise InputError(path, number, "expected 'digraph NAME {' (not a graphviz file?)")
            seen_digraph, depth = True, 1
            continue
        if closed:
            raise InputError(path, number, "text after the graph's closing '}'")
        if text.startswith("subgraph"):
            if legend_depth is None and "Legend" in text:
                legend_depth = depth
            depth += text.count("{")
            continue
        if text == "}":
            depth -= 1
            if legend_depth is not None and depth == legend_depth:
                legend_depth = None
            closed = depth == 0
            continue
        if legend_depth is not None:
            continue
        _parse_statement(path, number, text, nodes, edges)
    if not seen_digraph:
        raise InputError(path, 0, "empty: no 'digraph' in the file")
    if not closed:
        raise InputError(path, len(lines), "graph not closed by '}' (truncated file?)")
    return nodes, edges


def _parse_statement(path, number, text, nodes, edges):
    """Adds the node or edge of one statement line; ignores attribute lines."""
    if "->" in text:
        match = _EDGE.match(text)
        if not match:
            raise InputError(path, number, f"cannot parse edge: {text}")
        tail, head = _unquote(match.group(1)), _unquote(match.group(2))
        for node in (tail, head):
            if node not in nodes:
                raise InputError(path, number, f"edge uses undeclared node {node}")
        edges.append((tail, head))
        return
    match = _NODE.match(text)
    if match and match.group(1) not in ("node", "edge", "graph"):
        label = _LABEL.search(match.group(2))
        if not label:
            raise InputError(path, number, f"node without a label: {text}")
        nodes[_unquote(match.group(1))] = _label_names(label.group(1))
    elif text.startswith('"'):
        raise InputError(path, number, f"cannot parse node: {text}")


# --- target map --------------------------------------------------------------


def parse_targets(path):
    """Reads rover_targets.tsv into ({target: folder}, {alias: real target}).

    Lines are `target<TAB>folder`, or `alias<TAB>folder<TAB>real target`.
    """
    folders, aliases = {}, {}
    for number, line in enumerate(read_lines(path), 1):
        if not line.strip():
            continue
        fields = line.split("\t")
        if len(fields) not in (2, 3) or not all(field.strip() for field in fields):
            raise InputError(path, number, "expected 'target<TAB>folder[<TAB>aliased target]'")
        name, folder = fields[0], fields[1]
        if folder.startswith("/"):
            raise InputError(path, number, f"folder must be relative to the project root: {folder}")
        if len(fields) == 3:
            aliases[name] = fields[2]
            folders.setdefault(fields[2], folder)
            continue
        if folders.get(name, folder) != folder:
            raise InputError(path, number, f"{name} listed twice, in {folders[name]} and {folder}")
        folders[name] = folder
    if not folders:
        raise InputError(path, 0, "no targets in the file")
    return folders, aliases


# --- rules -------------------------------------------------------------------


def parse_rules(path):
    """Reads the rules file (format: see RULES_HELP) into a Rules tuple."""
    entries, allowed, reach = {}, set(), []
    for number, line in enumerate(read_lines(path), 1):
        words = line.split("#", 1)[0].split()
        if not words:
            continue
        keyword, args = words[0], words[1:]
        if keyword == "layer":
            if len(args) < 2 or not re.fullmatch(r"\d+", args[0]):
                raise InputError(path, number, "expected 'layer N FOLDER...'")
            _add_entries(path, number, entries, args[1:], Entry("layer", int(args[0]), number))
        elif keyword in ("exempt", "shared"):
            if not args:
                raise InputError(path, number, f"expected '{keyword} FOLDER...'")
            _add_entries(path, number, entries, args, Entry(keyword, None, number))
        elif keyword == "allow":
            if len(args) != 3 or args[1] != "->":
                raise InputError(path, number, "expected 'allow FOLDER -> FOLDER'")
            allowed.add((_folder_entry(args[0]), _folder_entry(args[2])))
        elif keyword == "must-not-reach":
            if len(args) < 3 or args[1] != "->":
                raise InputError(path, number, "expected 'must-not-reach TARGET -> PATTERN...'")
            reach.append(ReachRule(args[0], args[2:], number))
        else:
            raise InputError(path, number, f"unknown directive '{keyword}'")
    _check_allowed(path, entries, allowed)
    return Rules(entries, allowed, reach, path)


def _folder_entry(folder):
    """Normalises a folder as written in the rules file ("host/", "./hil")."""
    folder = folder.strip("/")
    while folder.startswith("./"):
        folder = folder[2:]
    return folder or "."


def _add_entries(path, number, entries, folders, entry):
    """Files each folder under `entry`; a folder may be placed only once."""
    for folder in map(_folder_entry, folders):
        if folder in entries:
            raise InputError(path, number, f"folder '{folder}' already placed on line {entries[folder].line}")
        entries[folder] = entry


def _check_allowed(path, entries, allowed):
    """An `allow` makes sense only between two layered folders."""
    for pair in sorted(allowed):
        for folder in pair:
            entry = entries.get(folder)
            if entry is None or entry.kind != "layer":
                raise InputError(path, 0, f"allow {pair[0]} -> {pair[1]}: '{folder}' is not in any layer")


def classify(folder, entries):
    """Returns the rules entry (folder key) covering `folder`, or None.

    The longest entry that is `folder` or a parent folder of it wins; "." only
    covers the root folder itself.
    """
    if folder == ".":
        return "." if "." in entries else None
    parts = folder.split("/")
    for end in range(len(parts), 0, -1):
        candidate = "/".join(parts[:end])
        if candidate in entries:
            return candidate
    return None


# --- graph -------------------------------------------------------------------


def build_graph(nodes, edges, aliases):
    """Returns ({target name: set of linked names}, {alias: real name}).

    Aliases come from the target map and from the node labels. A node labelled
    with an alias (older CMake versions) is merged into its real target;
    self-links (CMake draws one for each executable) are dropped.
    """
    aliases = dict(aliases)
    for name, node_aliases in nodes.values():
        for alias in node_aliases:
            aliases.setdefault(alias, name)
    names = {node: aliases.get(name, name) for node, (name, _) in nodes.items()}
    graph = {name: set() for name in names.values()}
    for tail, head in edges:
        if names[tail] != names[head]:
            graph[names[tail]].add(names[head])
    return graph, aliases


def _describe(name, folders):
    """Names a target with its folder, or an external library as itself."""
    return f"{name} ({folders[name]})" if name in folders else name


def check_unplaced(graph, folders, rules):
    """Reports project targets of the graph whose folder no rule covers."""
    violations = []
    for name in sorted(graph):
        if name in folders and classify(folders[name], rules.entries) is None:
            violations.append(f"{folders[name]}: {name}: folder is in no layer, exempt or shared rule of {rules.path}")
    return violations


def _edge_verdict(tail_key, head_key, rules):
    """Returns why a link from entry `tail_key` to entry `head_key` is forbidden, or None."""
    tail, head = rules.entries[tail_key], rules.entries[head_key]
    if tail.kind == "exempt" or head.kind == "shared" or tail_key == head_key:
        return None
    if tail.kind == "shared":
        return f"shared target in {tail_key} must not link project targets"
    if head.kind == "exempt":
        return f"{tail_key} must not link {head_key} (test and benchmark code)"
    if head.level < tail.level or (tail_key, head_key) in rules.allowed:
        return None
    return f"{tail_key} must not link {head_key}"


def check_layering(graph, folders, rules):
    """Reports each direct link that breaks the layer, allow, exempt and shared rules."""
    violations = []
    for tail in sorted(graph):
        tail_key = classify(folders[tail], rules.entries) if tail in folders else None
        if tail_key is None:
            continue
        for head in sorted(graph[tail]):
            head_key = classify(folders[head], rules.entries) if head in folders else None
            if head_key is None:
                continue
            reason = _edge_verdict(tail_key, head_key, rules)
            if reason:
                violations.append(f"{folders[tail]}: {tail} -> {_describe(head, folders)}: {reason}")
    return violations


def _matcher(pattern, folders, aliases):
    """Returns a predicate on target names for one must-not-reach pattern."""
    target = aliases.get(pattern, pattern)
    if target in folders:
        return lambda name: name == target
    lowered = pattern.lower()
    return lambda name: name not in folders and lowered in name.lower()


def _shortest_path(graph, start, accept):
    """Breadth-first search: the shortest link path from `start` to a node `accept`s, or None."""
    parents = {start: None}
    queue = collections.deque([start])
    while queue:
        node = queue.popleft()
        if node != start and accept(node):
            path = []
            while node is not None:
                path.append(node)
                node = parents[node]
            return path[::-1]
        for head in sorted(graph.get(node, ())):
            if head not in parents:
                parents[head] = node
                queue.append(head)
    return None


def check_reach(graph, folders, aliases, rules, warn):
    """Reports, per must-not-reach rule and pattern, the shortest path that breaks it.

    A rule whose target is not in the graph cannot be checked; `warn` gets a
    note instead, since optional targets are left out when their libraries are
    missing.
    """
    violations = []
    for rule in rules.reach:
        start = aliases.get(rule.target, rule.target)
        if start not in graph:
            warn(f"{rules.path}:{rule.line}: {rule.target} is not in the link graph; rule not checked")
            continue
        for pattern in rule.patterns:
            path = _shortest_path(graph, start, _matcher(pattern, folders, aliases))
            if path:
                shown = " -> ".join([path[0]] + [_describe(name, folders) for name in path[1:]])
                where = folders.get(start, "?")
                rule_text = f"{rule.target} must not reach {pattern} ({rules.path}:{rule.line})"
                violations.append(f"{where}: {shown}: {rule_text}")
    return violations


def check(dot_path, targets_path, rules_path, warn):
    """Runs every check on the three input files; returns the violation lines."""
    nodes, edges = parse_dot(dot_path)
    folders, aliases = parse_targets(targets_path)
    rules = parse_rules(rules_path)
    graph, aliases = build_graph(nodes, edges, aliases)
    if nodes and not any(name in folders for name in graph):
        raise InputError(targets_path, 0, f"none of its targets is in {dot_path} (files of different builds?)")
    return (
        check_unplaced(graph, folders, rules)
        + check_layering(graph, folders, rules)
        + check_reach(graph, folders, aliases, rules, warn)
    )


def parse_args(argv):
    """Parses the command line; argparse exits with status 2 on bad usage."""
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[1],
        epilog=RULES_HELP
        + "\nviolation lines: 'FOLDER: TAIL -> HEAD (HEAD FOLDER): RULE' for a direct\n"
        "link, 'FOLDER: TARGET -> ... -> LIBRARY: RULE (FILE:LINE)' for a reach rule.\n"
        "exit status: 0 clean, 1 violations, 2 unreadable input or bad usage.\n\n"
        "example:\n"
        "  cmake -S . -B build/check --graphviz=build/check/graph/rover.dot\n"
        "  scripts/check_link_graph.py --dot build/check/graph/rover.dot \\\n"
        "      --targets build/check/rover_targets.tsv --rules tests/architecture/link_rules.txt",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--dot", required=True, help="graph written by cmake --graphviz=FILE")
    parser.add_argument("--targets", required=True, help="rover_targets.tsv from the same configure (build folder)")
    parser.add_argument("--rules", required=True, help="rules file, e.g. tests/architecture/link_rules.txt")
    return parser.parse_args(argv)


def _warn(message):
    """Prints a note that does not change the exit status."""
    print(f"check_link_graph: note: {message}", file=sys.stderr)


def main(argv=None):
    """Command-line entry point; returns the exit status."""
    args = parse_args(argv)
    try:
        violations = check(args.dot, args.targets, args.rules, _warn)
    except InputError as error:
        print(f"check_link_graph: {error}", file=sys.stderr)
        return 2
    for line in violations:
        print(line)
    if violations:
        print(f"check_link_graph: {len(violations)} violation(s) of {args.rules}", file=sys.stderr)
        return 1
    print(f"check_link_graph: link graph follows {args.rules}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
