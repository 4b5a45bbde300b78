#!/usr/bin/env python3
"""Checks that the rooms of src/ depend downward, with no circle.

Reads every .c, .h (src/) and .cl (kernels/) file, and draws an edge from
file A to file B when A includes B (#include "...", resolved against A's
folder, then src/) or when A calls a function that B defines (a function
defined without `static` in B.c). A file pair x.c/x.h is one node; a room is
a top-level folder of src/ (src/matrix/opencl/ is part of the matrix room;
kernels/ is a room of its own). Fails (exit 1), naming the circle, when:
  - two nodes reach each other (a circle at file level);
  - two rooms reach each other (a circle at room level);
  - an #include "..." resolves to no file (meshfmm.h, the public header in
    include/, aside);
  - a .c calls a function defined in another node without including that
    node's header (directly, or through its own header); functions of the
    public header, which every file includes, aside.
Prints a one-line summary. Standard library only:
    python3 scripts/check_rooms.py
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SRC = os.path.join(ROOT, "src")
KERNELS = os.path.join(ROOT, "kernels")
PUBLIC = {"meshfmm.h"}  # include/: the public header, below every room

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
# A function definition: a name and its parameters followed by a body, not
# preceded by `static` on its line (parameters may hold one level of
# parentheses, e.g. a function pointer).
DEFINITION = re.compile(
    r"^(?!static\b)(?:[A-Za-z_][\w \t\*]*?[\s\*])([A-Za-z_]\w*)\s*"
    r"\(((?:[^;{}()]|\([^()]*\))*)\)\s*\{",
    re.M,
)
CALL = re.compile(r"\b([A-Za-z_]\w*)\s*\(")


def strip(text):
    """The text without comments and string or character literals (their
    newlines kept, so that line anchors still work)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def sources():
    for top in (SRC, KERNELS):
        for folder, _, names in os.walk(top):
            for name in sorted(names):
                if name.endswith((".c", ".h", ".cl")):
                    yield os.path.join(folder, name)


def node_of(path):
    rel = os.path.relpath(path, ROOT)
    return os.path.splitext(rel)[0]


def room_of(node):
    parts = node.split(os.sep)
    return parts[1] if parts[0] == "src" else parts[0]


def resolve(path, name):
    for base in (os.path.dirname(path), SRC):
        candidate = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(candidate):
            return candidate
    return None


def find_cycle(graph):
    """A circle of the directed graph {node: set(nodes)} as a list of nodes
    (first == last), or None."""
    state = {}
    for start in sorted(graph):
        if state.get(start):
            continue
        stack = [(start, iter(sorted(graph[start])))]
        path = [start]
        state[start] = 1
        while stack:
            node, children = stack[-1]
            child = next(children, None)
            if child is None:
                state[node] = 2
                stack.pop()
                path.pop()
            elif state.get(child) == 1:
                return path[path.index(child):] + [child]
            elif not state.get(child):
                state[child] = 1
                path.append(child)
                stack.append((child, iter(sorted(graph.get(child, ())))))
    return None


def main():
    problems = []
    texts = {}
    includes = {}  # node -> set of nodes included
    direct = {}  # .c path -> set of nodes it includes itself or via its own header
    for path in sources():
        with open(path, encoding="utf-8") as f:
            raw = f.read()
        texts[path] = strip(raw)
        node = node_of(path)
        edges = includes.setdefault(node, set())
        for name in INCLUDE.findall(raw):
            if name in PUBLIC:
                continue
            target = resolve(path, name)
            if target is None:
                problems.append("%s: #include \"%s\" names no file" % (os.path.relpath(path, ROOT), name))
                continue
            direct.setdefault(path, set()).add(node_of(target))
            if node_of(target) != node:
                edges.add(node_of(target))

    with open(os.path.join(ROOT, "include", "meshfmm.h"), encoding="utf-8") as f:
        public = set(re.findall(r"\b(mfmm_\w+)\s*\(", strip(f.read())))
    defined = {}  # function -> node defining it (non-static, in a .c)
    for path, text in texts.items():
        if path.endswith(".c"):
            for name, _ in DEFINITION.findall(text):
                defined[name] = node_of(path)

    graph = {node: set(edges) for node, edges in includes.items()}
    n_calls = 0
    for path, text in texts.items():
        if not path.endswith(".c"):
            continue
        node = node_of(path)
        seen = direct.get(path, set()) | {node}
        own_header = os.path.splitext(path)[0] + ".h"
        if os.path.isfile(own_header):
            seen |= direct.get(own_header, set())
        for name in set(CALL.findall(text)):
            target = defined.get(name)
            if target is None or target == node:
                continue
            n_calls += 1
            graph[node].add(target)
            header = os.path.isfile(os.path.join(ROOT, target + ".h"))
            if header and name not in public and target not in seen:
                problems.append("%s calls %s (%s.c) without including %s.h"
                                % (os.path.relpath(path, ROOT), name, target, target))

    cycle = find_cycle(graph)
    if cycle:
        problems.append("circle between files: " + " -> ".join(cycle))
    rooms = {}
    for node, edges in graph.items():
        room = room_of(node)
        rooms.setdefault(room, set())
        for target in edges:
            if room_of(target) != room:
                rooms[room].add(room_of(target))
    room_cycle = find_cycle(rooms)
    if room_cycle:
        problems.append("circle between rooms: " + " -> ".join(room_cycle))

    for p in problems:
        print("check_rooms: " + p, file=sys.stderr)
    n_edges = sum(len(e) for e in graph.values())
    summary = "%d files in %d nodes, %d rooms, %d edges (includes and %d calls across files)" % (
        len(texts), len(graph), len(rooms), n_edges, n_calls)
    if problems:
        print("check_rooms: FAILED (%d problems): %s" % (len(problems), summary))
        return 1
    order = []
    left = {r: set(e) for r, e in rooms.items()}
    while left:
        ready = sorted(r for r, e in left.items() if not (e & set(left)))
        order += ready
        for r in ready:
            del left[r]
    print("check_rooms: OK, no circle: %s; rooms bottom up: %s" % (summary, " < ".join(order)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
