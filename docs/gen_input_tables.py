#!/usr/bin/env python3
"""Regenerates the settings tables of docs/input.md from `mica help <command>` (run after changing a schema;
tests/cli/docs.sh fails when a setting is missing from the page). Usage: python3 docs/gen_input_tables.py"""
import re
import subprocess

def table(command, prefix=''):
    """The settings of `mica help <command>`: per setting a line of path, type, default and range (a choice
    list wrapped after a '|', under the range column), then its description, indented and wrapped."""
    out = subprocess.run(['bin/mica', 'help', command], capture_output=True, text=True, check=True).stdout.splitlines()
    start = [k for k, line in enumerate(out) if re.match(r'setting +type +default +range$', line)][0]
    header = out[start]
    cols = [header.index(word) for word in ('setting', 'type', 'default', 'range')]
    keys = []
    for line in out[start + 2:]:
        if not line.strip():
            continue
        if not line.startswith(' '):
            keys.append([line[cols[j]:(cols[j + 1] if j + 1 < len(cols) else None)].strip() for j in range(4)] + [''])
        elif line.startswith(' ' * cols[3]):
            keys[-1][3] += ('' if keys[-1][3].endswith('|') else ' ') + line.strip()
        else:
            keys[-1][4] += (' ' if keys[-1][4] else '') + line.strip()
    rows = ['| setting | type | default | range | meaning |', '|---|---|---|---|---|']
    for f in keys:
        if not f[0].startswith(prefix):
            continue
        rows.append('| `%s` | %s | %s | %s | %s |' % (f[0], f[1], f[2].replace('|', '\\|'), f[3].replace('|', '\\|'), f[4].replace('|', '\\|')))
    return '\n'.join(rows) + '\n'

doc = open('docs/input.md').read()
for command, marker, prefix in (('run', 'This table is `mica help run`', ''),
                                ('study', 'This table is the `study.*` part of `mica help study`', 'study.'),
                                ('mls', 'This table is `mica help mls`', '')):
    end = doc.index(marker)
    start = doc.rindex('| setting | type | default | range | meaning |', 0, end)
    doc = doc[:start] + table(command, prefix) + '\n' + doc[end:]
open('docs/input.md', 'w').write(doc)
