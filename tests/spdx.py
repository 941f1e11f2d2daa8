#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""spdx.py ROOT [--check]: put 'SPDX-License-Identifier: BSD-3-Clause' in the first lines of every
project source file (C, C++, headers, Python, shell, make, CMake, JS/HTML templates we own)."""
import os, sys, subprocess
ROOT = sys.argv[1]; CHECK = '--check' in sys.argv
TAG = 'SPDX-License-Identifier: BSD-3-Clause'
STYLE = {'.c': '/* %s */', '.h': '/* %s */', '.cpp': '// %s', '.hpp': '// %s', '.py': '# %s',
         '.sh': '# %s', '.mk': '# %s', '.cmake': '# %s', '.js': '// %s', '.ld': '/* %s */',
         '.toml': '# %s', '.in': '# %s'}
files = subprocess.run(['git', '-C', ROOT, 'ls-files'], capture_output=True, text=True).stdout.split()
bad = []
for f in files:
    base = os.path.basename(f); ext = os.path.splitext(f)[1]
    if base == 'Makefile' or base == 'run':
        ext = '.mk' if base == 'Makefile' else '.sh'
    if ext not in STYLE or f.startswith('build/'):
        continue
    p = os.path.join(ROOT, f)
    with open(p, encoding='utf-8', errors='surrogateescape') as fh:
        lines = fh.read().split('\n')
    if any(TAG in l for l in lines[:5]):
        continue
    if CHECK:
        bad.append(f); continue
    line = STYLE[ext] % TAG
    at = 1 if lines and lines[0].startswith('#!') else 0
    lines.insert(at, line)
    with open(p, 'w', encoding='utf-8', errors='surrogateescape') as fh:
        fh.write('\n'.join(lines))
if CHECK:
    for f in bad: print('no SPDX line:', f)
    print(('FAIL' if bad else 'PASS') + ': spdx (%d files without the licence line)' % len(bad))
    sys.exit(1 if bad else 0)
