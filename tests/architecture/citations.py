#!/usr/bin/env python3
"""Checks that comments cite documents a cloner can read.

docs/architecture.md §8: a comment cites an equation, docs/architecture.md or a docs/*.md
section, never an issue number (issues live outside the repository) and never a file outside the
repository (e.g. ../shared/design.md). Scans the source and build files of the repository; each
finding is printed as FILE:LINE: text. Usage: citations.py REPO_ROOT
"""
import os
import re
import sys

FOLDERS = ('lib', 'data_gen', 'apps', 'python', 'tests', 'fuzz', 'cmake', 'scripts', 'examples')
EXTENSIONS = ('.h', '.hpp', '.cpp', '.cc', '.in', '.py', '.cmake', '.txt', '.sh', '.pyi', '.toml')
FORBIDDEN = [
    (re.compile(r'\bissues? #?\d+', re.I), 'cites an issue number'),
    (re.compile(r'\bdesign(\.md)? §', re.I), 'cites the design notes outside the repository (docs/architecture.md)'),
    (re.compile(r'\.\./shared/|shared/design\.md'), 'cites a file outside the repository'),
]


def files(root):
    for folder in FOLDERS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, folder)):
            dirnames[:] = [d for d in dirnames if d not in ('__pycache__', 'architecture')]
            for name in filenames:
                if name.endswith(EXTENSIONS) or name in ('CMakeLists.txt',) or '.' not in name:
                    yield os.path.join(dirpath, name)
    for name in ('CMakeLists.txt', 'CMakePresets.json', 'pyproject.toml', 'README.md'):
        if os.path.exists(os.path.join(root, name)):
            yield os.path.join(root, name)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else '.'
    problems = 0
    for path in files(root):
        try:
            text = open(path, encoding='utf-8').read()
        except (UnicodeDecodeError, OSError):
            continue
        for number, line in enumerate(text.splitlines(), 1):
            for pattern, why in FORBIDDEN:
                if pattern.search(line):
                    print(f'{os.path.relpath(path, root)}:{number}: {why}: {line.strip()[:120]}')
                    problems += 1
    print(f'{problems} citations that a cloner cannot read')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
