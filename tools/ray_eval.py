#!/usr/bin/env python3
"""Evaluate marionette GA generations on a Ray cluster.

This program speaks marionette's JSON-lines evaluation protocol (marionette-eval/3) on its own
standard input and output, exactly as `marionette eval --stdin` does, so the engine's GA uses it
as an evaluator (scene field `evaluator: Command(["python3", "tools/ray_eval.py"])`) while the GA
loop, its checkpoints and its bits stay in the engine. Behind it, each Ray actor holds one
long-lived `marionette eval --stdin` worker that uses all the cores of its node; a generation's
genomes are split into one contiguous chunk per actor, and the replies are returned in index
order.

On a laptop (a local Ray started by this program):
    marionette run scenes/evolve_fall.ron --set 'evaluator={"Command":["python3","tools/ray_eval.py"]}'
On a cluster (the engine and this program run on the head node; actors on every node):
    ray job submit --working-dir . -- marionette run scenes/evolve_fall.ron \
        --set 'evaluator={"Command":["python3","tools/ray_eval.py","--address","auto"]}'

Options: --address ADDR (Ray cluster, default: start a local one), --actors N (default: one
per node, or 1 locally), --worker PATH (the marionette binary, default `marionette` on PATH or
target/release/marionette), --cpus-per-actor N.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

PROTOCOL = "marionette-eval/3"


def refuse(where, line, why):
    """Ends this program with an error naming the line, as the engine's own worker does."""
    sys.exit(f"ray_eval: {where}: {why} (in {line.strip()[:120]!r})")


def message(line, where, tags):
    """The (tag, body) of a protocol line: one key among `tags` holding an object."""
    try:
        msg = json.loads(line)
    except json.JSONDecodeError as e:
        refuse(where, line, f"column {e.colno}: {e.msg}")
    if not isinstance(msg, dict) or len(msg) != 1:
        refuse(where, line, f"expected one message, one of {sorted(tags)}")
    (tag, body), = msg.items()
    if tag not in tags:
        refuse(where, line, f"unknown message `{tag}`, expected one of {sorted(tags)}")
    if not isinstance(body, dict):
        refuse(where, line, f"field `{tag}`: expected an object, found {body!r}")
    return tag, body


def find_worker(given):
    if given:
        return given
    here = os.path.dirname(os.path.abspath(__file__))
    local = os.path.join(here, "..", "target", "release", "marionette")
    if os.path.exists(local):
        return os.path.abspath(local)
    found = shutil.which("marionette")
    if found:
        return found
    sys.exit("ray_eval: no marionette binary (pass --worker PATH)")


def make_actor_class(ray):
    @ray.remote
    class Worker:
        """One long-lived `marionette eval --stdin` process."""

        def __init__(self, binary, header_line):
            self.binary = binary
            self.proc = subprocess.Popen(
                [binary, "eval", "--stdin"],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
                bufsize=1,
            )
            self.proc.stdin.write(header_line)
            self.proc.stdin.flush()

        def evaluate(self, lines):
            """Sends genome lines, then the batch end; returns the reply lines."""
            for line in lines:
                self.proc.stdin.write(line)
            self.proc.stdin.write(json.dumps({"evaluate": {"count": len(lines)}}) + "\n")
            self.proc.stdin.flush()
            replies = []
            while True:
                reply = self.proc.stdout.readline()
                if not reply:
                    raise RuntimeError(
                        f"{self.binary} eval --stdin closed its output after {len(replies)} "
                        f"of {len(lines)} replies (exit status {self.proc.poll()})")
                if "done" in json.loads(reply):
                    return replies
                replies.append(reply)

        def close(self):
            self.proc.stdin.close()
            self.proc.wait()
            return self.proc.returncode

    return Worker


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--address", default=None)
    ap.add_argument("--actors", type=int, default=None)
    ap.add_argument("--worker", default=None)
    ap.add_argument("--cpus-per-actor", type=float, default=None)
    args = ap.parse_args()

    import ray  # imported here so --help works without Ray

    header_line = sys.stdin.readline()
    header = json.loads(header_line)
    if not isinstance(header, dict) or set(header) != {"protocol", "problem"}:
        refuse("request line 1", header_line, "expected the header {\"protocol\", \"problem\"}")
    if header.get("protocol") != PROTOCOL:
        sys.exit(f"ray_eval: protocol {header.get('protocol')!r} is not {PROTOCOL!r}")

    ray.init(address=args.address, include_dashboard=False, log_to_driver=False,
             logging_level="ERROR")
    nodes = [n for n in ray.nodes() if n.get("Alive")]
    n_actors = args.actors or max(1, len(nodes))
    cpus = args.cpus_per_actor or max(1.0, ray.cluster_resources().get("CPU", 1.0) / n_actors)
    Worker = make_actor_class(ray).options(num_cpus=cpus)
    binary = find_worker(args.worker)
    actors = [Worker.remote(binary, header_line) for _ in range(n_actors)]

    batch = []
    for number, line in enumerate(sys.stdin, start=2):
        if not line.strip():
            continue
        # The workers check each genome line's fields; this checks the batch's shape.
        tag, body = message(line, f"request line {number}", {"genome", "evaluate"})
        if tag == "genome":
            batch.append(line if line.endswith("\n") else line + "\n")
            continue
        if body.get("count") != len(batch) or len(body) != 1:
            refuse(f"request line {number}", line,
                   f"field `evaluate.count`: the batch holds {len(batch)} genomes")
        # Contiguous chunks, one per actor; replies carry their index.
        k = max(1, -(-len(batch) // len(actors)))
        chunks = [batch[i:i + k] for i in range(0, len(batch), k)]
        futures = [a.evaluate.remote(c) for a, c in zip(actors, chunks)]
        replies = [r for rs in ray.get(futures) for r in rs]
        replies.sort(key=lambda r: next(iter(json.loads(r).values()))["index"])
        out = "".join(replies) + json.dumps({"done": {"count": len(batch)}}) + "\n"
        sys.stdout.write(out)
        sys.stdout.flush()
        batch = []
    if batch:
        sys.exit(f"ray_eval: the input ended inside a batch of {len(batch)} genomes")
    ray.get([a.close.remote() for a in actors])
    ray.shutdown()


if __name__ == "__main__":
    main()
