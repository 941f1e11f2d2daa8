#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""The public symbol contract of libocc.a (issue 17, "Symbols").

The library exports the documented API (every function and object declared in a header under
include/occmap/, any subfolder) and nothing else with the public prefix `occ_`; a function or
table shared between library files but not declared publicly carries the internal prefix `occi_`.

  symbols.py rename [ROOT]        compute the internal list from the sources and rename every use
                                  (occ_x -> occi_x, word-bounded) under src/ tests/ bench/ tools/
                                  port/ include/. Idempotent; assumes no layout of src/ (every
                                  *.c below it is read). Prints the internals that only one file
                                  uses (candidates for `static`, or removal when never called).
  symbols.py list [ROOT]          print the internal list (old -> new) without touching anything.
  symbols.py selftest LIB DIR     the check must fail on two broken copies of LIB made in DIR.
  symbols.py check LIB [ROOT]     the `make test` step: nm -g --defined-only LIB must export only
                                  public occ_ names and occi_ names, and every public declaration
                                  must be defined in LIB or, for host-only APIs, in port/; a
                                  portable header (include/occmap/*.h, not host/) declares none
                                  that only port/posix defines.

Why here (tests/) and one file: the rename and the check read "what is public" with the same
parser, and the check is what keeps the rename true; tools/ is the shipped `occmap` CLI.
The parser is a small C tokenizer, not a compiler: comments, strings and preprocessor lines are
dropped, then file-scope items are read (function definitions, declarations, objects). The check
cross-checks it against nm, so a parser miss shows up as a failing step, not a silent pass.
"""
import os
import shutil
import re
import subprocess
import sys

PUBLIC = "occ_"
INTERNAL = "occi_"
RENAME_DIRS = ("src", "tests", "bench", "tools", "port", "include")
RENAME_EXT = (".c", ".h", ".cpp", ".hpp", ".cc", ".mk", ".sh", ".py")
NOT_NAMES = {"__attribute__", "__attribute", "__declspec", "_Pragma", "sizeof", "_Alignas",
             "_Static_assert", "defined"}

_LEX = re.compile(r"""
    (?P<ws>\s+)
  | (?P<comment>//[^\n]*|/\*.*?\*/)
  | (?P<string>"(?:\\.|[^"\\\n])*"|'(?:\\.|[^'\\\n])*')
  | (?P<ident>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<number>\.?[0-9](?:[eEpP][+-]|[A-Za-z0-9_.])*)
  | (?P<punct>.)
""", re.S | re.X)


def strip_preprocessor(text):
    """Blank every preprocessor line (with its backslash continuations), and the code under
    `#ifdef OCC_TESTING` up to its #else / #endif: test builds only, never in the library the
    check reads (the release build)."""
    out, cont, depth, skip_at = [], False, 0, None
    for line in text.split("\n"):
        directive = cont or line.lstrip().startswith("#")
        cont = directive and line.endswith("\\")
        word = line.lstrip()[1:].split() if directive and line.lstrip().startswith("#") else []
        if word[:1] in (["if"], ["ifdef"], ["ifndef"]):
            depth += 1
            if skip_at is None and word[:2] == ["ifdef", "OCC_TESTING"]:
                skip_at = depth
        elif word[:1] in (["else"], ["elif"]) and skip_at == depth:
            skip_at = None
        elif word[:1] == ["endif"]:
            skip_at = None if skip_at == depth else skip_at
            depth -= 1
        out.append("" if directive or skip_at is not None else line)
    return "\n".join(out)


def tokens(text):
    # Comments go first so that a '#' or quote inside one cannot confuse the line stripper.
    text = re.sub(r"/\*.*?\*/|//[^\n]*", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    for m in _LEX.finditer(strip_preprocessor(text)):
        kind = m.lastgroup
        if kind in ("ws", "comment"):
            continue
        yield "STR" if kind == "string" else m.group(0)


def declared_name(item):
    """The name a file-scope item declares, and whether it is a function."""
    depth = 0
    for i, tok in enumerate(item):
        if tok in "([":
            if tok == "(" and depth == 0 and i > 0 and is_name(item[i - 1]) \
                    and not (i > 1 and item[i - 2] == "("):
                return item[i - 1], True
            depth += 1
        elif tok in ")]":
            depth -= 1
        elif depth == 0 and tok in ("=", ",", ";") and i > 0 and is_name(item[i - 1]):
            return item[i - 1], False
    for i, tok in enumerate(item):         # an object declared as an array: `T name[N];`
        if tok == "[" and i > 0 and is_name(item[i - 1]):
            return item[i - 1], False
    return None, False


def is_name(tok):
    return re.match(r"[A-Za-z_]\w*$", tok) is not None and tok not in NOT_NAMES \
        and not tok.isupper()


def file_scope_items(text):
    """Yield (tokens, has_body) for each file-scope item of a C file."""
    item, depth, body = [], 0, False
    for tok in tokens(text):
        if depth > 0:
            depth += {"{": 1, "}": -1}.get(tok, 0)
            if depth == 0 and body:
                yield item, True
                item, body = [], False
            continue
        if tok == "{":
            if item[-2:] == ["extern", "STR"]:    # extern "C" { ... }: its items are file scope
                item = item[:-2]
                continue
            depth, body = 1, bool(item) and item[-1] == ")" and "typedef" not in item \
                and "=" not in item
            continue
        if tok == "}":                            # the end of extern "C"
            continue
        item.append(tok)
        if tok == ";":
            yield item, False
            item = []


def external_items(text):
    """(name, kind) for each item with external linkage: kind is 'def' (a definition in this
    file) or 'decl' (an extern declaration)."""
    for item, has_body in file_scope_items(text):
        if "typedef" in item or "static" in item or "_Static_assert" in item:
            continue
        name, is_func = declared_name(item)
        if name is None:
            continue
        if has_body:
            yield name, "def"
        elif is_func or "extern" in item:
            yield name, "decl"
        elif item[0] not in ("struct", "union", "enum") or "=" in item or len(item) > 4:
            yield name, "def"                     # an object definition: `const T name[] = ...;`


def walk(root, top, exts):
    base = os.path.join(root, top)
    for d, dirs, files in os.walk(base):
        dirs.sort()
        for f in sorted(files):
            if f.endswith(exts):
                yield os.path.join(d, f)


def read(path):
    with open(path, encoding="utf-8", errors="surrogateescape") as fh:
        return fh.read()


def public_declarations(root, portable_only=False):
    """Names declared under include/occmap/ (portable_only: not in its host/ folder)."""
    names = set()
    for path in walk(root, "include/occmap", (".h",)):
        if portable_only and os.path.basename(os.path.dirname(path)) == "host":
            continue
        names.update(n for n, _ in external_items(read(path)))
    return names


def definitions(root, top):
    """{name: defining file} for every external definition in the .c files under top/."""
    defs = {}
    for path in walk(root, top, (".c",)):
        for name, kind in external_items(read(path)):
            if kind == "def":
                defs[name] = os.path.relpath(path, root)
    return defs


def internal_renames(root):
    """{occ_x: occi_x} for every library definition that is not public, and for every occi_x
    already defined (so a file merged in later with old spellings is caught up)."""
    public = public_declarations(root)
    renames = {}
    for name in definitions(root, "src"):
        if name.startswith(PUBLIC) and name not in public:
            renames[name] = INTERNAL + name[len(PUBLIC):]
        elif name.startswith(INTERNAL):
            renames[PUBLIC + name[len(INTERNAL):]] = name
    return renames


def rename_files(root, renames):
    if not renames:
        return []
    pattern = re.compile(r"\b(" + "|".join(sorted(map(re.escape, renames), key=len,
                                                   reverse=True)) + r")\b")
    changed = []
    for top in RENAME_DIRS:
        for path in walk(root, top, RENAME_EXT):
            if os.path.abspath(path) == os.path.abspath(__file__):
                continue
            text = read(path)
            new = "\n".join(realigned(text.split("\n"), pattern, renames))
            if new != text:
                with open(path, "w", encoding="utf-8", errors="surrogateescape") as fh:
                    fh.write(new)
                changed.append(os.path.relpath(path, root))
    return changed


def realigned(lines, pattern, renames):
    """Rename in each line, and keep continuation lines aligned to an open parenthesis that a
    longer name moved (`f(a,\n  b)`): only a line indented exactly one past that parenthesis."""
    open_parens = []                      # (old column, new column) of each unclosed '('
    for line in lines:
        if not line.strip() or line.lstrip().startswith("#"):
            open_parens = []
        indent = len(line) - len(line.lstrip(" "))
        new_indent = indent
        if open_parens and indent == open_parens[-1][0] + 1:
            new_indent = open_parens[-1][1] + 1
        shift, col_map, pos = new_indent - indent, [], indent
        out = [" " * new_indent]
        for m in pattern.finditer(line, indent):
            out.append(line[pos:m.start()])
            out.append(renames[m.group(1)])
            col_map.append((m.end(), shift))
            shift += len(renames[m.group(1)]) - len(m.group(1))
            pos = m.end()
        out.append(line[pos:])
        col_map.append((len(line) + 1, shift))
        for col, ch in enumerate(line):
            if ch == "(":
                moved = next(s for end, s in col_map if col < end)
                open_parens.append((col, col + moved))
            elif ch == ")" and open_parens:
                open_parens.pop()
        yield "".join(out)


def single_file_internals(root):
    """Internal names that no file other than their definer uses. A header counts only when it
    names one more than once (a static inline caller, not just the prototype)."""
    defs = definitions(root, "src")
    users = {n: set() for n, f in defs.items() if n.startswith(INTERNAL)}
    word = re.compile(r"\b" + INTERNAL + r"\w+")
    for top in RENAME_DIRS:
        for path in walk(root, top, (".c", ".cpp", ".cc", ".h", ".hpp")):
            rel = os.path.relpath(path, root)
            found = word.findall(read(path))
            for n in set(found):
                if n in users and (found.count(n) > 1 or not path.endswith((".h", ".hpp"))):
                    users[n].add(rel)
    for n in sorted(users):
        if users[n] <= {defs[n]}:
            calls = len(re.findall(r"\b" + n + r"\b", read(os.path.join(root, defs[n]))))
            yield n, defs[n], calls > 1


def nm_defined(lib):
    out = subprocess.run(["nm", "-g", "--defined-only", lib], check=True,
                         capture_output=True, text=True).stdout
    return {f[2] for f in (line.split() for line in out.splitlines()) if len(f) == 3}


def problems(lib, root):
    """Every way LIB breaks the contract, as messages (empty when it holds)."""
    exported = nm_defined(lib)
    public = public_declarations(root)
    host_only = set(definitions(root, "port"))
    errors = []
    for name in sorted(exported):
        if name.startswith(PUBLIC) and name not in public:
            errors.append(f"exported but not declared in include/occmap: {name} (make it static, "
                          f"or run tests/symbols.py rename to make it {INTERNAL}...)")
        elif not name.startswith((PUBLIC, INTERNAL)):
            errors.append(f"exported without the occ_/occi_ prefix: {name}")
    for name in sorted(public - exported - host_only):
        errors.append(f"declared in include/occmap but defined neither in {lib} nor in port/: "
                      f"{name}")
    # What firmware sees (include/occmap/*.h) is defined in the library or by every platform:
    # a function only port/posix defines is host-only and belongs under include/occmap/host/.
    posix_only = set(definitions(root, "port/posix")) - set(definitions(root, "port/baremetal"))
    for name in sorted(public_declarations(root, True) & posix_only - exported):
        errors.append(f"a portable header declares {name}, defined only in port/posix: "
                      f"declare it under include/occmap/host/")
    # The parser against nm: every library definition it saw must be exported, and the reverse.
    parsed = set(definitions(root, "src"))
    for name in sorted(parsed ^ exported):
        where = "nm lists it, the source parser missed it" if name in exported \
            else "the parser sees a definition nm does not list"
        errors.append(f"parser mismatch: {name}: {where} (is {lib} up to date?)")
    return errors, exported, public, host_only


def check(lib, root):
    errors, exported, public, host_only = problems(lib, root)
    for e in errors:
        print("FAIL symbols:", e)
    if errors:
        print(f"FAIL symbols: {len(errors)} problem(s)")
        return 1
    n_pub = len([n for n in exported if n.startswith(PUBLIC)])
    n_int = len([n for n in exported if n.startswith(INTERNAL)])
    print(f"PASS symbols: {lib} exports {n_pub} public occ_ and {n_int} internal occi_ symbols; "
          f"all {len(public)} public declarations defined ({len(public & host_only - exported)} "
          f"host-only, in port/)")
    return 0


def selftest_portable(lib, root, work):
    """The check must fail on a tree whose portable occ_port.h declares a POSIX-only link call."""
    tree = os.path.join(work, "tree")
    shutil.rmtree(tree, ignore_errors=True)
    shutil.copytree(os.path.join(root, "include"), os.path.join(tree, "include"))
    for top in ("src", "port"):
        os.symlink(os.path.abspath(os.path.join(root, top)), os.path.join(tree, top))
    with open(os.path.join(tree, "include", "occmap", "occ_port.h"), "a") as fh:
        fh.write("void occ_link_close(void *link);\n")
    expect = "a portable header declares occ_link_close, defined only in port/posix"
    seen = any(e.startswith(expect) for e in problems(lib, tree)[0])
    print(f"{'PASS' if seen else 'FAIL'} symbols-selftest portable: the check "
          f"{'reports' if seen else 'misses'} \"{expect}\"")
    return 0 if seen else 1


def selftest(lib, root, work):
    """The check must fail on two broken copies of LIB: one with an extra occ_ function that no
    public header declares, one without the member that defines occ_err_str."""
    os.makedirs(work, exist_ok=True)
    extra_c, extra_o = os.path.join(work, "extra.c"), os.path.join(work, "extra.o")
    with open(extra_c, "w") as fh:
        fh.write("int occ_symbols_selftest_extra(void);\n"
                 "int occ_symbols_selftest_extra(void) { return 1; }\n")
    subprocess.run(["gcc", "-c", extra_c, "-o", extra_o], check=True)
    members = subprocess.run(["nm", "-A", "-g", "--defined-only", lib], check=True,
                             capture_output=True, text=True).stdout
    err_member = next(line.split(":")[1] for line in members.splitlines()
                      if line.endswith(" occ_err_str"))
    cases = [("extra", ["ar", "rcs", None, extra_o],
              "exported but not declared in include/occmap: occ_symbols_selftest_extra"),
             ("missing", ["ar", "d", None, err_member],
              "declared in include/occmap but defined neither in")]
    status = selftest_portable(lib, root, work)
    for name, cmd, expect in cases:
        broken = os.path.join(work, f"libocc-{name}.a")
        shutil.copyfile(lib, broken)
        subprocess.run([broken if c is None else c for c in cmd], check=True)
        errors = problems(broken, root)[0]
        seen = any(e.startswith(expect) for e in errors)
        print(f"{'PASS' if seen else 'FAIL'} symbols-selftest {name}: the check "
              f"{'reports' if seen else 'misses'} \"{expect}\"")
        status |= 0 if seen else 1
    return status


def main(argv):
    if len(argv) >= 4 and argv[1] == "selftest":
        return selftest(argv[2], ".", argv[3])
    if len(argv) < 2 or argv[1] not in ("rename", "list", "check"):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    if argv[1] == "check":
        if len(argv) < 3:
            print("usage: symbols.py check LIB [ROOT]", file=sys.stderr)
            return 2
        return check(argv[2], argv[3] if len(argv) > 3 else ".")
    root = argv[2] if len(argv) > 2 else "."
    renames = internal_renames(root)
    for old in sorted(renames):
        print(f"{old} -> {renames[old]}")
    if argv[1] == "rename":
        changed = rename_files(root, renames)
        print(f"rename: {len(changed)} file(s) changed" + "".join(f"\n  {c}" for c in changed))
        for name, path, called in single_file_internals(root):
            what = "used only here: make it static, drop the prefix" if called \
                else "never called: remove it"
            print(f"note: {name} ({path}): {what}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
