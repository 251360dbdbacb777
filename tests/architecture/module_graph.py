#!/usr/bin/env python3
"""Checks the module graph stated in docs/architecture.md against the code.

The page's table "Module graph" lists every module, its folder and the modules it depends on.
This script derives the real graph from two sources and requires both to equal the page:
  - the `#include` lines of each module's sources (an include of another module's header is an
    arrow), and
  - for library modules, the weft_* targets named in `weft_module(... DEPS ... PRIVATE_DEPS ...)`
    of the module's CMakeLists.txt (a link is an arrow).
It also requires the graph to be acyclic. Usage: module_graph.py REPO_ROOT [--print]
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]((?:weft|data_gen)/[^">]+)[">]', re.M)
ROW = re.compile(r'^\|\s*`([a-z0-9_]+)`\s*\|\s*`([^`]+)`\s*\|([^|]*)\|', re.M)
SOURCE_EXT = ('.h', '.hpp', '.cpp', '.cc', '.in')


def read_page(root):
    path = os.path.join(root, 'docs', 'architecture.md')
    text = open(path, encoding='utf-8').read()
    start = text.find('<!-- module-graph:begin -->')
    end = text.find('<!-- module-graph:end -->')
    if start < 0 or end < start:
        sys.exit(f'{path}: no <!-- module-graph:begin/end --> block')
    modules = {}
    for name, folder, deps in ROW.findall(text[start:end]):
        modules[name] = (folder.strip().rstrip('/'), set(re.findall(r'`([a-z0-9_]+)`', deps)))
    if not modules:
        sys.exit(f'{path}: the module-graph block has no rows')
    return modules


def module_of_header(header, folders):
    """The module whose folder holds `header` (an include path rooted at lib/ or the repo)."""
    best = None
    for name, folder in folders.items():
        for prefix in (folder + '/', folder.removeprefix('lib/') + '/'):
            if header.startswith(prefix) and (best is None or len(prefix) > len(best[1])):
                best = (name, prefix)
    return best[0] if best else None


def include_arrows(root, modules):
    folders = {name: folder for name, (folder, _) in modules.items()}
    arrows = {name: set() for name in modules}
    unknown = []
    for name, folder in folders.items():
        base = os.path.join(root, folder)
        nested = [f for n, f in folders.items() if n != name and f.startswith(folder + '/')]
        for dirpath, dirnames, filenames in os.walk(base):
            rel = os.path.relpath(dirpath, root)
            if any(rel == f or rel.startswith(f + '/') for f in nested):
                dirnames[:] = []
                continue
            dirnames[:] = [d for d in dirnames if d not in ('tests', '__pycache__')]
            for fname in filenames:
                if not fname.endswith(SOURCE_EXT):
                    continue
                text = open(os.path.join(dirpath, fname), encoding='utf-8', errors='replace').read()
                for header in INCLUDE.findall(text):
                    target = module_of_header(header, folders)
                    if target is None:
                        unknown.append(f'{rel}/{fname}: #include "{header}" is in no module of the page')
                    elif target != name:
                        arrows[name].add(target)
    return arrows, unknown


def cmake_arrows(root, modules):
    arrows = {}
    for name, (folder, _) in modules.items():
        path = os.path.join(root, folder, 'CMakeLists.txt')
        if not os.path.exists(path):
            continue
        text = re.sub(r'#[^\n]*', '', open(path, encoding='utf-8').read())
        call = re.search(r'weft_module\(\s*(\w+)(.*?)\)', text, re.S)
        if not call:
            continue
        deps = set()
        for target in re.findall(r'\bweft_([a-z0-9_]+)\b', call.group(2)):
            if target in modules and target != name:
                deps.add(target)
        arrows[name] = deps
    return arrows


def find_cycle(graph):
    state = {}

    def visit(node, stack):
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return stack + [node, nxt]
            if state.get(nxt) is None:
                cycle = visit(nxt, stack + [node])
                if cycle:
                    return cycle
        state[node] = 2
        return None

    for node in sorted(graph):
        if state.get(node) is None:
            cycle = visit(node, [])
            if cycle:
                return cycle
    return None


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else '.'
    modules = read_page(root)
    includes, problems = include_arrows(root, modules)
    links = cmake_arrows(root, modules)
    if '--print' in sys.argv:
        for name in modules:
            real = includes[name] | links.get(name, set())
            print(f'{name}: {", ".join(sorted(real)) or "-"}')
        return 0
    for name, (folder, stated) in sorted(modules.items()):
        if not os.path.isdir(os.path.join(root, folder)):
            problems.append(f'{name}: folder {folder} does not exist')
            continue
        real = includes[name] | links.get(name, set())
        for extra in sorted(real - stated):
            why = 'includes' if extra in includes[name] else 'links'
            problems.append(f'{name} {why} {extra}, but docs/architecture.md does not list that arrow')
        for missing in sorted(stated - real):
            problems.append(f'docs/architecture.md lists {name} -> {missing}, but {name} neither includes nor links it')
        if name in links:
            for unlinked in sorted(includes[name] - links[name]):
                problems.append(f'{name} includes {unlinked} without linking weft_{unlinked} in {folder}/CMakeLists.txt')
    cycle = find_cycle({name: stated for name, (_, stated) in modules.items()})
    if cycle:
        problems.append('the stated module graph has a cycle: ' + ' -> '.join(cycle))
    for p in problems:
        print('module graph:', p)
    print(f'{len(modules)} modules checked, {len(problems)} problems')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
