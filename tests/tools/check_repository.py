#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
"""The repository's own rules, checked on the tracked files (CTest: repository.rules).

  check_repository.py SOURCE_DIR [SHARED_DIR]

1. Licence: every source and build file carries an SPDX-License-Identifier line near its top.
2. Layout: include/lumx/ holds only the version header template at its top (everything else lives in a
   module folder); every compiled file under src/ is listed in src/CMakeLists.txt; docs/architecture.md
   names every public header and every module folder, so the map stays true.
3. Module order: docs/architecture.md states it on one line, "Module order (...): a → b → ...", and
   every public header of include/lumx/M/ and every file of src/M/ includes (as <lumx/N/...> or "N/...")
   only modules N that come before M or M itself, so the include graph has no cycle.
4. Public headers stay declarations first: none over 800 lines (MAX_HEADER_LINES), and no function body
   that is not a template's over 60 lines (MAX_INLINE_BODY_LINES) in one; the engine lives in src/.
5. Third-party data: no tracked file has the same bytes as a file under SHARED_DIR/data (real-world data is
   read there in place, never committed). Without SHARED_DIR the check is reported as skipped, except
   under CI (CI=true), which always has it.
Prints one line per finding and exits 1 if there is any.
"""
import hashlib
import re
import os
import subprocess
import sys

SOURCE_SUFFIXES = ('.h', '.hpp', '.cpp', '.py', '.sh', '.cmake')
SOURCE_NAMES = ('CMakeLists.txt', 'version.h.in', 'lumxConfig.cmake.in', 'run')


def tracked_files(root):
    """Files git tracks (plus untracked, not ignored ones), or every file when this is not a checkout."""
    try:
        out = subprocess.run(['git', '-C', root, 'ls-files', '-z', '--cached', '--others', '--exclude-standard'],
                             check=True, capture_output=True).stdout
        files = [f for f in out.decode('utf-8').split('\0') if f]
    except (OSError, subprocess.CalledProcessError):
        files = []
        for base, dirs, names in os.walk(root):
            dirs[:] = [d for d in dirs if not d.startswith('.') and not d.startswith('build') and d != 'out']
            files += [os.path.relpath(os.path.join(base, n), root) for n in names]
    return sorted(f for f in files if os.path.isfile(os.path.join(root, f)))


def is_source(path):
    name = os.path.basename(path)
    if path.startswith('tests/data/') and not name.endswith('.py'):
        return False  # test fixtures are data, not source
    return name.endswith(SOURCE_SUFFIXES) or name in SOURCE_NAMES


def sha256(path):
    h = hashlib.sha256()
    with open(path, 'rb') as f:
        for block in iter(lambda: f.read(1 << 20), b''):
            h.update(block)
    return h.hexdigest()


MAX_HEADER_LINES = 800
MAX_INLINE_BODY_LINES = 60
CONTROL = re.compile(r'\b(if|for|while|switch|catch|return|else|do)\s*(\(|$)')
FUNCTION_HEAD = re.compile(r'\)\s*(const|noexcept|override|final|mutable|&|->[^;{}()]*|\s)*$'
                           r'|\)\s*:\s*[\s\S]*\)\s*$')  # a signature, or a constructor's initialiser list


def code_only(text):
    """The text with comments, string and character literals blanked, line breaks kept."""
    out = re.sub(r'/\*[\s\S]*?\*/', lambda m: re.sub(r'[^\n]', ' ', m.group()), text)
    out = re.sub(r'R"([^(]*)\([\s\S]*?\)\1"', lambda m: re.sub(r'[^\n]', ' ', m.group()), out)
    out = re.sub(r'"(\\.|[^"\\\n])*"', '""', out)
    out = re.sub(r"'(\\.|[^'\\\n])+'", "' '", out)
    return re.sub(r'//[^\n]*', '', out)


def long_inline_bodies(text):
    """(line, lines) of every function body outside any other function, not a template's, over the limit."""
    code = code_only(text)
    found = []
    stack = []  # per open brace: (kind, template, start line); kind 'function' or 'block'
    last = 0  # where the current head starts: after the last ';', '{' or '}'
    line = 1
    for i, c in enumerate(code):
        if c == '\n':
            line += 1
        elif c == '{':
            head = code[last:i].strip()
            inside_function = any(k == 'function' for k, _, _ in stack)
            is_function = (not inside_function and FUNCTION_HEAD.search(head) is not None
                           and not CONTROL.search(head.split('\n')[-1].strip()) and '](' not in head.replace(' ', ''))
            template = bool(re.search(r'\btemplate\s*<', head)) or any(t for _, t, _ in stack)
            stack.append(('function' if is_function else 'block', template, line))
            last = i + 1
        elif c == '}':
            if stack:
                kind, template, start = stack.pop()
                if kind == 'function' and not template and line - start - 1 > MAX_INLINE_BODY_LINES:
                    found.append((start, line - start - 1))
            last = i + 1
        elif c == ';':
            last = i + 1
    return found


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    root = os.path.abspath(sys.argv[1])
    shared = os.path.abspath(sys.argv[2]) if len(sys.argv) == 3 else ''
    files = tracked_files(root)
    findings = []

    # 1. Licence.
    for f in files:
        if not is_source(f):
            continue
        with open(os.path.join(root, f), 'r', encoding='utf-8', errors='replace') as fh:
            head = [next(fh, '') for _ in range(5)]
        if not any('SPDX-License-Identifier: Apache-2.0' in line for line in head):
            findings.append(f'{f}:1: licence: no "SPDX-License-Identifier: Apache-2.0" line in its first 5 lines')
    for f in ('LICENSE', 'NOTICE', 'THIRD_PARTY_NOTICES.md'):
        if f not in files:
            findings.append(f'{f}: licence: missing')

    # 2. Layout.
    top = [f for f in files if f.startswith('include/lumx/') and f.count('/') == 2]
    for f in top:
        if os.path.basename(f) not in ('version.h.in', 'lumx.h'):
            findings.append(f'{f}: layout: a header at the top of include/lumx/ (put it in a module folder)')
    with open(os.path.join(root, 'src', 'CMakeLists.txt'), encoding='utf-8') as fh:
        src_cmake = fh.read()
    for f in files:
        if f.startswith('src/') and f.endswith('.cpp') and f[len('src/'):] not in src_cmake:
            findings.append(f'{f}: layout: not listed in src/CMakeLists.txt')
    with open(os.path.join(root, 'docs', 'architecture.md'), encoding='utf-8') as fh:
        architecture = fh.read()
    modules = sorted({f.split('/')[2] for f in files if f.startswith('include/lumx/') and f.count('/') >= 3})
    for m in modules:
        if f'lumx/{m}/' not in architecture and f'`{m}/`' not in architecture:
            findings.append(f'docs/architecture.md: layout: module folder include/lumx/{m}/ is not described')
    for f in files:
        if f.startswith('include/lumx/') and f.endswith('.h') and '/detail/' not in f:
            name = os.path.basename(f)
            if name not in architecture:
                findings.append(f'docs/architecture.md: layout: public header {f} is not named')

    # 3. Module order.
    order_line = re.search(r'^Module order[^:]*:(.*)$', architecture, re.MULTILINE)
    if not order_line:
        findings.append('docs/architecture.md: module order: no line "Module order (...): a \u2192 b \u2192 ..."')
    else:
        order = [m.strip(' `.') for m in order_line.group(1).split('\u2192')]
        rank = {m: i for i, m in enumerate(order)}
        for m in modules:
            if m not in rank:
                findings.append(f'docs/architecture.md: module order: module {m} is not in the stated order')
        for f in files:
            parts = f.split('/')
            if f.startswith('include/lumx/') and len(parts) >= 4 and f.endswith('.h'):
                m = parts[2]
            elif f.startswith('src/') and len(parts) >= 3 and f.endswith(('.h', '.cpp')):
                m = parts[1]
            else:
                continue
            if m not in rank:
                continue
            with open(os.path.join(root, f), encoding='utf-8', errors='replace') as fh:
                for n, line in enumerate(fh, 1):
                    for d in re.findall(r'^\s*#\s*include\s*[<"](?:lumx/)?([a-z_]+)/', line):
                        if d in rank and rank[d] > rank[m]:
                            findings.append(f'{f}:{n}: module order: {m} includes {d}, which comes after it')

    # 4. Public headers: declarations first.
    for f in files:
        if f.startswith('include/lumx/') and f.endswith('.h'):
            with open(os.path.join(root, f), encoding='utf-8', errors='replace') as fh:
                text = fh.read()
            lines = text.count('\n')
            if lines > MAX_HEADER_LINES:
                findings.append(f'{f}: header size: {lines} lines, over {MAX_HEADER_LINES} (move the engine to src/)')
            for start, n in long_inline_bodies(text):
                findings.append(f'{f}:{start}: header size: a {n}-line function body, over {MAX_INLINE_BODY_LINES} '
                                '(define it in src/)')

    # 5. Third-party data.
    data = os.path.join(shared, 'data') if shared else ''
    if data and os.path.isdir(data):
        theirs = {}
        for base, _, names in os.walk(data):
            for n in names:
                p = os.path.join(base, n)
                if os.path.isfile(p) and os.path.getsize(p) > 0:
                    theirs.setdefault(os.path.getsize(p), []).append(p)
        for f in files:
            p = os.path.join(root, f)
            candidates = theirs.get(os.path.getsize(p), [])
            if candidates:
                digest = sha256(p)
                for c in candidates:
                    if sha256(c) == digest:
                        findings.append(f'{f}: third-party data: same bytes as {os.path.relpath(c, shared)} '
                                        '(read it in place from ../shared/data instead)')
                        break
    elif os.environ.get('CI', '') not in ('', '0', 'false'):
        findings.append(f'{shared or "SHARED_DIR"}/data: third-party data: missing under CI, cannot check')
    else:
        print('skipped: third-party data check (../shared/data not present)')

    for line in findings:
        print(line)
    print(f'{len(files)} files checked, {len(findings)} findings')
    return 1 if findings else 0


if __name__ == '__main__':
    sys.exit(main())
