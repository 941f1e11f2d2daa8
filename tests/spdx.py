#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""spdx.py ROOT [--check]: put 'SPDX-License-Identifier: BSD-3-Clause' in the first lines of every
project source and build file git tracks under ROOT (C, C++, headers, Python, shell, make, CMake,
pkg-config and CMake templates, linker scripts, JS we own); with --check only list the files
without it (exit 1 when there are any).
spdx.py --self-test: the check and the fix on a scratch git repository holding one file of every
kind STYLE and NAMES know (CMakeLists.txt among them) plus files they must leave alone."""
import os
import subprocess
import sys
import tempfile

TAG = 'SPDX-License-Identifier: BSD-3-Clause'
# Comment style by extension. X.in (a configure template) takes the style of X's extension when
# it has a known one (foo.h.in: C), else '#' (occmap.pc.in, occmapConfig.cmake.in).
STYLE = {'.c': '/* %s */', '.h': '/* %s */', '.cpp': '// %s', '.hpp': '// %s', '.py': '# %s',
         '.sh': '# %s', '.mk': '# %s', '.cmake': '# %s', '.js': '// %s', '.ld': '/* %s */',
         '.toml': '# %s', '.pc': '# %s', '.in': '# %s'}
# Build files known by their whole name (no extension, or one that says nothing: .txt).
NAMES = {'Makefile': '# %s', 'GNUmakefile': '# %s', 'makefile': '# %s',
         'CMakeLists.txt': '# %s', 'run': '# %s'}


def rule_of(path):
    """The NAMES or STYLE key that decides a tracked file's comment format, or None when the file
    carries no licence line."""
    base = os.path.basename(path)
    if base in NAMES:
        return base
    stem, ext = os.path.splitext(base)
    if ext == '.in' and os.path.splitext(stem)[1] in STYLE:
        return os.path.splitext(stem)[1]
    return ext if ext in STYLE else None


def style_of(path):
    rule = rule_of(path)
    return None if rule is None else NAMES.get(rule) or STYLE[rule]


def scan(root, check):
    """Files without the line (check), or add it to them; returns the list of those files."""
    files = subprocess.run(['git', '-C', root, 'ls-files'], capture_output=True, text=True,
                           check=True).stdout.split('\n')
    bad = []
    for f in filter(None, files):
        style = style_of(f)
        if style is None or f.startswith('build/'):
            continue
        p = os.path.join(root, f)
        with open(p, encoding='utf-8', errors='surrogateescape') as fh:
            lines = fh.read().split('\n')
        if any(TAG in line for line in lines[:5]):
            continue
        bad.append(f)
        if check:
            continue
        at = 1 if lines and lines[0].startswith('#!') else 0
        lines.insert(at, style % TAG)
        with open(p, 'w', encoding='utf-8', errors='surrogateescape') as fh:
            fh.write('\n'.join(lines))
    return bad


# The self-test's repository: path -> (content, the line the fix must put first (after a
# shebang), or None: left alone).
SELF_TEST = {
    'tests/install_consumer/CMakeLists.txt': ('project(x C)\n', '# %s'),
    'cmake/extra.cmake': ('set(A 1)\n', '# %s'),
    'port/occmapConfig.cmake.in': ('@PACKAGE_INIT@\n', '# %s'),
    'port/occmap.pc.in': ('prefix=@PREFIX@\n', '# %s'),
    'port/config.h.in': ('#define X @X@\n', '/* %s */'),
    'Makefile': ('all:\n', '# %s'),
    'sub/GNUmakefile': ('all:\n', '# %s'),
    'old/makefile': ('all:\n', '# %s'),
    'pkg/occmap.spec.in': ('Name: occmap\n', '# %s'),
    'src/sources.mk': ('A := 1\n', '# %s'),
    'src/a.c': ('int a;\n', '/* %s */'),
    'include/a.h': ('int a(void);\n', '/* %s */'),
    'bench/b.cpp': ('int b;\n', '// %s'),
    'bench/b.hpp': ('int b();\n', '// %s'),
    'tools/t.py': ('#!/usr/bin/env python3\nprint(1)\n', '# %s'),
    'tools/t.sh': ('#!/bin/sh\ntrue\n', '# %s'),
    '.ci/run': ('#!/usr/bin/env bash\nmake test\n', '# %s'),
    'tools/view.js': ('let a;\n', '// %s'),
    'port/fw.ld': ('MEMORY {}\n', '/* %s */'),
    'port/pyproject.toml': ('[project]\n', '# %s'),
    'README.md': ('# readme\n', None),
    'data/notes.txt': ('text\n', None),
    'data/ref.json': ('{}\n', None),
    'already.c': ('/* ' + TAG + ' */\nint x;\n', None),
}


def self_test():
    """The fix adds exactly the expected line to every kind of file, --check finds each of them
    before and none after, and the files that take no line are untouched."""
    fails = []
    untested = sorted((set(STYLE) | set(NAMES)) - {rule_of(p) for p in SELF_TEST})
    if untested:
        fails.append('no file of these kinds in SELF_TEST: %s' % ' '.join(untested))
    with tempfile.TemporaryDirectory() as root:
        for path, (text, _) in SELF_TEST.items():
            os.makedirs(os.path.join(root, os.path.dirname(path)), exist_ok=True)
            with open(os.path.join(root, path), 'w', encoding='utf-8') as fh:
                fh.write(text)
        subprocess.run(['git', '-C', root, 'init', '-q'], check=True)
        subprocess.run(['git', '-C', root, 'add', '-A'], check=True)
        want = sorted(p for p, (_, s) in SELF_TEST.items() if s is not None and p != 'already.c')
        if sorted(scan(root, True)) != want:
            fails.append('--check lists %s, want %s' % (sorted(scan(root, True)), want))
        scan(root, False)
        for path, (text, style) in SELF_TEST.items():
            with open(os.path.join(root, path), encoding='utf-8') as fh:
                got = fh.read()
            expect = text
            if style is not None and path != 'already.c':
                head = text.split('\n', 1)
                if text.startswith('#!'):
                    expect = head[0] + '\n' + style % TAG + '\n' + head[1]
                else:
                    expect = style % TAG + '\n' + text
            if got != expect:
                fails.append('%s after the fix: %r, want %r' % (path, got, expect))
        left = scan(root, True)
        if left:
            fails.append('--check after the fix still lists %s' % left)
    for f in fails:
        print('FAIL: spdx self-test: ' + f)
    print('%s: spdx self-test (%d files, every kind of STYLE and NAMES)' % (
        'FAIL' if fails else 'PASS', len(SELF_TEST)))
    return 1 if fails else 0


def main(argv):
    if '--self-test' in argv:
        return self_test()
    root, check = argv[1], '--check' in argv
    bad = scan(root, check)
    if check:
        for f in bad:
            print('no SPDX line:', f)
        print(('FAIL' if bad else 'PASS') + ': spdx (%d files without the licence line)' % len(bad))
        return 1 if bad else 0
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
