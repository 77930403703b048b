#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Checks the relative links of README.md and docs/**/*.md: each target file
exists, and each #anchor names a heading of it (GitHub's anchor rules)."""
import os, re, sys, glob

def anchors(path):
    out, seen, fence = set(), {}, False
    for line in open(path, encoding='utf-8'):
        if line.startswith('```'):
            fence = not fence
            continue
        if fence:
            continue
        m = re.match(r'^(#{1,6})\s+(.*?)\s*#*\s*$', line)
        if not m:
            continue
        a = m.group(2).strip().lower()
        a = re.sub(r'[^\w\- ]', '', a).replace(' ', '-')
        n = seen.get(a, 0)
        seen[a] = n + 1
        out.add(a if n == 0 else '%s-%d' % (a, n))
    return out

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
files = [os.path.join(root, 'README.md')] + sorted(glob.glob(os.path.join(root, 'docs', '**', '*.md'), recursive=True))
bad = 0
for f in files:
    text = open(f, encoding='utf-8').read()
    text = re.sub(r'```.*?```', '', text, flags=re.S)   # no links in code blocks
    for m in re.finditer(r'\]\(([^)\s]+)\)', text):
        target = m.group(1)
        if re.match(r'^[a-z]+:', target):
            continue
        path, _, anchor = target.partition('#')
        full = os.path.normpath(os.path.join(os.path.dirname(f), path)) if path else f
        if not os.path.exists(full):
            print('%s: no such file: %s' % (f, target)); bad += 1; continue
        if anchor and os.path.isfile(full) and anchor not in anchors(full):
            print('%s: no heading #%s in %s' % (f, anchor, full)); bad += 1
print('%d files, %d bad links' % (len(files), bad))
sys.exit(1 if bad else 0)
