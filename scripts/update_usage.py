#!/usr/bin/env python3
"""Regenerates the help blocks of docs/usage.md from the built qsmesh: `qsmesh --help` and
`qsmesh COMMAND --help` for every command the general help lists, each verbatim in a fenced block
between the markers

    <!-- qsmesh-help TOPIC: ... -->
    ```text
    ...
    ```
    <!-- /qsmesh-help TOPIC -->

(TOPIC `qsmesh` for the general help). A block whose marker is missing is added at the end of the
file, a block for a command that no longer exists is removed. The test `UsageDoc.*`
(tests/drivers/test_usage_doc.cpp) fails until this has been run after a change of the help texts.

Usage: scripts/update_usage.py [--exe build/drivers/qsmesh] [--doc docs/usage.md] [--check]
  --check: change nothing, exit 1 (naming the blocks) when the file is out of date.
Uses only the standard library."""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GENERAL = "qsmesh"
BLOCK = re.compile(r"<!-- qsmesh-help (\S+?)[: ][^\n]*-->\n```text\n(.*?)```\n<!-- /qsmesh-help \1 -->\n",
                   re.S)


def commands(general_help):
    """The commands listed under 'commands:' in the general help, in order."""
    names, inside = [], False
    for line in general_help.splitlines():
        if line.strip() == "commands:":
            inside = True
        elif inside and not line.strip():
            break
        elif inside:
            m = re.match(r"^  ([a-z][a-z0-9-]*)\b", line)
            if m:
                names.append(m.group(1))
    return names


def help_text(exe, topic):
    args = [exe, "--help"] if topic == GENERAL else [exe, topic, "--help"]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"update_usage: {' '.join(args)} exited {r.returncode}: {r.stderr.strip()}")
    return r.stdout


def block(topic, text):
    command = "qsmesh --help" if topic == GENERAL else f"qsmesh {topic} --help"
    if not text.endswith("\n"):
        text += "\n"
    return (f"<!-- qsmesh-help {topic}: `{command}`, written by scripts/update_usage.py; do not edit -->\n"
            f"```text\n{text}```\n<!-- /qsmesh-help {topic} -->\n")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--exe", default=os.path.join(ROOT, "build", "drivers", "qsmesh"))
    p.add_argument("--doc", default=os.path.join(ROOT, "docs", "usage.md"))
    p.add_argument("--check", action="store_true")
    a = p.parse_args()
    if not os.access(a.exe, os.X_OK):
        sys.exit(f"update_usage: {a.exe} missing; build first (scripts/build.sh)")
    doc = open(a.doc).read()
    general = help_text(a.exe, GENERAL)
    topics = [GENERAL] + commands(general)
    texts = {t: (general if t == GENERAL else help_text(a.exe, t)) for t in topics}

    changed = []

    def replace(m):
        topic = m.group(1)
        if topic not in texts:
            changed.append(f"{topic} (removed: no such command)")
            return ""
        new = block(topic, texts[topic])
        if new != m.group(0):
            changed.append(topic)
        return new

    out = BLOCK.sub(replace, doc)
    present = {m.group(1) for m in BLOCK.finditer(doc)}
    for t in topics:
        if t not in present:
            changed.append(f"{t} (added)")
            out = out.rstrip("\n") + "\n\n" + block(t, texts[t])
    if not changed:
        print(f"update_usage: {a.doc} is up to date ({len(topics)} help blocks)")
        return 0
    if a.check:
        print(f"update_usage: {a.doc} is out of date: {', '.join(changed)}; run scripts/update_usage.py",
              file=sys.stderr)
        return 1
    with open(a.doc + ".tmp", "w") as f:
        f.write(out)
    os.replace(a.doc + ".tmp", a.doc)
    print(f"update_usage: {a.doc}: updated {', '.join(changed)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
