#!/usr/bin/env python3
"""Predicts the time of `qsmesh mesh` on P ranks x T threads from the --stats of one real run on one
rank, by replaying its measured per-face, per-stage times through the pipeline's scheduling rules
(docs/architecture.md, "Parallel model"):

- replicated stages (load, partition, quantize): every rank does the same work; as measured.
- curves: split by curve in rounds (--stats curve_rounds: the sampling, then the feature sizes);
  each round deals the curves over the P ranks by its weights, greedy longest first
  (greedy_partition, the pipeline's deal_by_weight), each rank runs its curves in curve order on
  T threads (list scheduling), then every curve's record is all-gathered (gathered on rank 0, one
  message per rank, and broadcast: the round's bytes three times at the bandwidth). The rest of
  the stage (the rounds' setup done by every rank, the last step on every curve) as measured.
  A run without curve_rounds keeps the stage replicated.
- load: replicated (every rank reads the file), except the faces' area integrals, split by face
  over the ranks (--stats load_rounds: dealt evenly by face id, all-gathered), replayed as a
  curves round is. A run without load_rounds keeps the whole stage replicated.
- partitioned stages (background, crossfield, sizemap, unstructured, pattern_compare, distance,
  pack):
  each rank
  runs the faces the METIS partition gives it, as TBB tasks in face order on T threads (list
  scheduling in that order); the stage ends when the slowest rank is done.
- dealt stages (patterns, improvement): all P x T threads take the next face from one shared
  counter, largest first by the pipeline's own keys (expected quads; the unstructured mesh's
  quads), i.e. list scheduling in that order over P x T workers; a face taken away from its owner
  is read from it first (MPI_Get), and each result goes back to its owner. A face's pattern fill
  splits its move search's batches over its rank's threads (batched_schedule; face_stats'
  pattern_layouts, pattern_batches, pattern_search); with one thread per rank its search's lent
  batches go over the ranks done with their faces instead (helped_schedule; pattern_layout_*,
  pattern_vector_lendable). A face improved in
  pieces (--task-quads; face_stats' stage_seconds.improvement_tasks: 2k + 1 piece times, or
  2k + 2 with the whole face after them) is k tasks in the first round, dealt with the whole
  faces, k + 1 in a second round after it (each piece keyed by the face's quads / pieces), and
  the whole face in a third (--pass-after-cuts); its cutting and merging (its improvement time
  less its tasks') runs on its owner between and after the rounds. A face whose two passes ran
  as two tasks (--second-pass-task; face_stats' stage_seconds.improvement_passes) is two tasks of
  the first round, the second passes dealt after every other task; the choice between them (its
  improvement time less the passes') runs on its owner after it.
- assemble: rank 0 unpacks and assembles every face (as measured) after receiving the other ranks'
  faces (bytes / bandwidth); the driver's later stages (statistics, write, ...) on rank 0 as
  measured.
- what a stage spent outside its faces in the measured run (setup, serial parts such as the size
  map's curve sizes and gradation) is added as measured, on every configuration.
- messages and reductions: each stage ends with an all-reduce (latency x ceil(log2 P)); the size
  map and the pattern stage add one each, the improvement an all-gather of 28 bytes a face and two
  window collectives; each dealt face costs one fetch-and-add; bytes moved cost bytes / bandwidth.
  Latencies and bandwidth come from --comm (scripts/mpi_costs.c's output), else the defaults below.

The faces' partition over P ranks is the real one when --partitions gives the JSON of
`qsmesh info MODEL --json --partition P,... --size-factor F` (the same METIS call and weights as
the run); otherwise a greedy longest-first partition of the faces by expected quads (said so in the
output).

Usage: python3 scripts/simulate_scaling.py STATS.json --configs 2x1,4,8,64x2 [--partitions INFO.json]
                 [--comm COSTS.json] [--real PxT=STATS.json ...] [--csv FILE] [--markdown]
A config "P" means P ranks x 1 thread. Exit codes: 0 success, 2 bad input."""
import argparse
import heapq
import json
import math
import sys

TOOL = "simulate_scaling"
REPLICATED = ["load", "curves", "partition", "quantize"]
# distance: the final mesh's distance to the CAD, each face on its owner (its curves' share, split
# over the ranks too, is in the stage's residual).
PARTITIONED = ["background", "crossfield", "sizemap", "unstructured", "pattern_compare", "distance",
               "pack"]
DEALT = ["patterns", "improvement"]
GATHER = ["assemble"]
# On-node defaults where no --comm is given (Open MPI, shared memory; mpi_costs on the 2-core
# development machine measured them of this order): seconds, bytes per second.
DEFAULT_COMM = {"allreduce_s": 5e-6, "fetch_and_add_s": 1e-6, "get_64k_s": 1e-5,
                "bandwidth_bytes_per_s": 5e9}
RECORD_BYTES = 28  # what every rank learns of every face before the improvement (improve.cpp)


class InputError(Exception):
    pass


def list_schedule(durations, workers):
    """Greedy list scheduling: each item, in the given order, goes to the worker that is free
    first (ties: the lowest worker). durations: a list of seconds, or of functions worker ->
    seconds (the cost may depend on who runs it). Returns (makespan, worker of each item, finish
    time of each worker)."""
    if workers < 1:
        raise ValueError("list_schedule: at least one worker")
    free = [(0.0, w) for w in range(workers)]
    heapq.heapify(free)
    assigned = []
    end = [0.0] * workers
    for d in durations:
        t, w = heapq.heappop(free)
        t += d(w) if callable(d) else d
        end[w] = t
        assigned.append(w)
        heapq.heappush(free, (t, w))
    return max(end) if end else 0.0, assigned, end


def batched_schedule(seconds, search, layouts, batches, threads):
    """A face's time when its move search's `layouts` (taking `search` of its `seconds`) come in
    `batches` laid out over `threads` at once: the serial rest, plus per batch ceil(layouts per
    batch / threads) layouts. Never more than the serial time."""
    if threads <= 1 or layouts <= 0 or batches <= 0 or search <= 0:
        return seconds
    search = min(search, seconds)
    per = search / layouts
    return min(seconds, seconds - search + per * batches * math.ceil(layouts / batches / threads))


def lent_batch_seconds(per, steps, per_step, planned, workers):
    """One lent batch of a move search (PatternFaceOptions::helpers) over `workers` (the owner and
    its helpers): it covers `steps` single steps of the rules reading `per_step` layouts each and
    plans `planned` layouts. With a worker for each it costs one layout; with fewer the deeper
    levels are left out and each step costs ceil(per_step / workers); never more than the serial
    steps."""
    serial = steps * per_step
    cost = min(serial, steps * math.ceil(per_step / workers))
    if workers >= planned:
        cost = min(cost, 1)
    return per * cost


def helped_schedule(seconds, layout_seconds, layouts, batches, lent_batches, lent_layouts,
                    helpers):
    """A face's pattern time when its move search's layouts are lent to `helpers` free ranks
    throughout (face_stats' pattern_layout_*): the layouts the rules read take `layout_seconds`
    of its `seconds`, one layout layout_seconds / layouts; the rest stays serial; each of the
    `lent_batches` costs lent_batch_seconds. Never more than the serial time."""
    if helpers <= 0 or layouts <= 0 or layout_seconds <= 0 or lent_batches <= 0 or batches <= 0:
        return seconds
    layout_seconds = min(layout_seconds, seconds)
    per = layout_seconds / layouts
    one = lent_batch_seconds(per, batches / lent_batches, layouts / batches,
                             lent_layouts / lent_batches, helpers + 1)
    return min(seconds, seconds - layout_seconds + lent_batches * one)


def greedy_partition(weights, parts):
    """Longest-first greedy partition (the stand-in for METIS without --partitions): each face, by
    decreasing weight, to the part with the least weight so far."""
    order = sorted(range(len(weights)), key=lambda f: (-weights[f], f))
    _, assigned, _ = list_schedule([weights[f] for f in order], parts)
    part = [0] * len(weights)
    for f, p in zip(order, assigned):
        part[f] = p
    return part


def levels(p):
    return math.ceil(math.log2(p)) if p > 1 else 0


def split_rounds(stats, key, name):
    """The rounds of --stats `key` (parallel::SplitRound), each with its items' times under
    "item_seconds"."""
    rounds = []
    for k, r in enumerate(stats.get(key, [])):
        r = dict(r)
        r.setdefault("item_seconds", r.get("curve_seconds", []))
        if len(r.get("weights", [])) != len(r["item_seconds"]):
            raise InputError(f"{name}: {key} round {k + 1} has {len(r.get('weights', []))} "
                             f"weights for {len(r['item_seconds'])} item times")
        rounds.append(r)
    return rounds


class Run:
    """What the simulation reads of one --stats JSON."""

    def __init__(self, stats, name="stats", any_ranks=False):
        if stats.get("ranks", 1) != 1 and not any_ranks:
            raise InputError(f"{name}: the base run must be on one rank (it has {stats['ranks']})")
        faces = stats.get("face_stats")
        if not faces or "stage_seconds" not in faces[0]:
            raise InputError(f"{name}: no per-face stage times (face_stats[].stage_seconds): a "
                             "quad-stage run of a qsmesh built with them is needed")
        self.threads = int(stats.get("threads", 1))
        self.ranks = int(stats.get("ranks", 1))
        self.seconds = {k: v for k, v in stats["seconds"].items() if k != "total"}
        self.total = stats["seconds"].get("total", sum(self.seconds.values()))
        self.faces = sorted(faces, key=lambda f: f["face"])
        self.n = len(self.faces)
        self.t = {s: [f["stage_seconds"].get(s, 0.0) for f in self.faces]
                  for s in PARTITIONED + DEALT}
        self.expected = [f["stage_seconds"].get("expected_quads", 0.0) for f in self.faces]
        self.improve_quads = [f["stage_seconds"].get("improvement_quads", 0) for f in self.faces]
        self.improve_tasks = [f["stage_seconds"].get("improvement_tasks", []) for f in self.faces]
        # A whole face's two improvement passes dealt as two tasks (--second-pass-task).
        self.improve_passes = [f["stage_seconds"].get("improvement_passes", []) for f in self.faces]
        self.bytes = [f["stage_seconds"].get("bytes", 0) for f in self.faces]
        # The pattern fill's move search: layouts read, the batches they come in, its seconds.
        self.pattern_layouts = [f["stage_seconds"].get("pattern_layouts", 0) for f in self.faces]
        self.pattern_batches = [f["stage_seconds"].get("pattern_batches", 0) for f in self.faces]
        self.pattern_search = [f["stage_seconds"].get("pattern_search", 0.0) for f in self.faces]
        # ... and what lending it to free ranks would make of it (a run on one rank counts the
        # lent batches as if enough ranks were free).
        ss = [f["stage_seconds"] for f in self.faces]
        self.layout_seconds = [x.get("pattern_layout_seconds", 0.0) for x in ss]
        self.layout_batches = [x.get("pattern_layout_batches", 0) for x in ss]
        self.layout_vectors = [x.get("pattern_layout_vectors", 0) for x in ss]
        self.lendable = [x.get("pattern_vector_lendable", 0) > 0 for x in ss]
        self.by_pattern = [f.get("method", "").startswith("pattern") for f in self.faces]
        # pack: a face's stage_seconds.pack is its output and statistics; writing its record comes
        # after (and cannot time itself into it). On one rank and one thread the stage's rest is
        # that writing, per face too: dealt over the faces by their record bytes.
        if (self.threads == 1 and int(stats.get("ranks", 1)) == 1 and "pack" in self.seconds
                and sum(self.bytes) > 0):
            rest = max(0.0, self.seconds["pack"] - sum(self.t["pack"]))
            total_bytes = sum(self.bytes)
            self.t["pack"] = [x + rest * b / total_bytes for x, b in zip(self.t["pack"],
                                                                          self.bytes)]
        self.face_rank = [f.get("rank", 0) for f in self.faces]
        # The rounds split by item over the ranks (parallel::SplitRound): the curves stage's, by
        # curve, and the load's face measurements, by face. Older runs name the items' times
        # curve_seconds.
        self.curve_rounds = split_rounds(stats, "curve_rounds", name)
        self.load_rounds = split_rounds(stats, "load_rounds", name)


class Simulator:
    def __init__(self, run, partitions=None, comm=None, residual=None):
        self.run = run
        self.partitions = partitions or {}
        self.comm = dict(DEFAULT_COMM)
        if comm:
            self.comm.update({k: v for k, v in comm.items() if k in DEFAULT_COMM and v and v > 0})
        self.greedy = []  # rank counts partitioned greedily
        # What each stage spent outside its faces in the measured run.
        self.residual = {}
        self.busy = []
        if residual is not None:  # a replay: the base run's
            self.residual = residual
            return
        base = self.compute(1, run.threads)
        for s, v in run.seconds.items():
            self.residual[s] = max(0.0, v - base.get(s, 0.0)) if s in base else None

    def partition(self, p):
        if p == 1:
            return [0] * self.run.n
        part = self.partitions.get(str(p))
        if part is not None:
            if len(part) != self.run.n:
                raise InputError(f"partition for {p} ranks has {len(part)} faces, the run "
                                 f"{self.run.n}")
            return part
        if p not in self.greedy:
            self.greedy.append(p)
        return greedy_partition([max(1.0, e) for e in self.run.expected], p)

    def allreduce(self, p):
        return self.comm["allreduce_s"] * levels(p)

    def curve_round(self, r, p, t):
        """One curves round's split part on p ranks x t threads: the curves dealt by weight, each
        rank's in curve order on its t threads; the slowest rank."""
        part = greedy_partition(r["weights"], p) if p > 1 else [0] * len(r["weights"])
        per_rank = [[] for _ in range(p)]
        for c, sec in enumerate(r["item_seconds"]):
            per_rank[part[c]].append(sec)
        return max(list_schedule(mine, t)[0] for mine in per_rank)

    def curve_gather(self, r, p):
        """A curves round's all-gather on p ranks: gathered on rank 0 (the sizes, then one message
        per rank) and broadcast to all; its bytes three times at the bandwidth."""
        if p == 1:
            return 0.0
        return (3 * r["bytes"] / self.comm["bandwidth_bytes_per_s"]
                + self.comm["allreduce_s"] * (p - 1) + 2 * self.allreduce(p))

    def replay_rounds(self, stage, rounds, p, t):
        """A stage with rounds split by item (the curves, the load) on p ranks x t threads: the
        measured stage with each round's split part and all-gather (as the measured run did them)
        replaced by those on p x t."""
        run = self.run
        v = run.seconds[stage]
        for r in rounds:
            v += (self.curve_round(r, p, t) + self.curve_gather(r, p)
                  - self.curve_round(r, run.ranks, run.threads) - self.curve_gather(r, run.ranks))
        return max(0.0, v)

    def curves(self, p, t):
        return self.replay_rounds("curves", self.run.curve_rounds, p, t)

    def get_cost(self, nbytes):
        # A face read from its owner: one lock/get/unlock round, its bytes at the bandwidth.
        return self.comm["fetch_and_add_s"] + nbytes / self.comm["bandwidth_bytes_per_s"]

    def compute(self, p, t):
        """The per-face part of each split stage on p ranks x t threads (no residuals, no
        messages): {stage: seconds}."""
        run = self.run
        part = self.partition(p)
        out = {}
        self.busy = [0.0] * p  # each rank's own time in the split stages (rank_busy_seconds)
        for s in PARTITIONED:
            worst = 0.0
            for r in range(p):
                mine = [run.t[s][f] for f in range(run.n) if part[f] == r]
                span = list_schedule(mine, t)[0]
                self.busy[r] += span
                worst = max(worst, span)
            out[s] = worst
        out.update(self.dealt(p, t, part, messages=False)[0])
        return out

    def dealt(self, p, t, part, messages=True):
        """Dealt stages: ({stage: seconds}, {stage: seconds of messages after the dealing})."""
        run = self.run
        bw = self.comm["bandwidth_bytes_per_s"]
        fetch = self.comm["fetch_and_add_s"] if (messages and p > 1) else 0.0
        times, extra = {}, {}
        patterns = [[(f, run.expected[f], 0, sec, run.bytes[f])
                     for f, sec in enumerate(self.helped_pattern_seconds(p, t, fetch))]]
        improvement, owner_work = self.improvement_rounds()
        for s, rounds in (("patterns", patterns), ("improvement", improvement)):
            times[s] = 0.0
            extra[s] = 0.0
            ends = [0.0] * (p * t)
            for items in rounds:
                if not items:
                    continue
                order = sorted(items, key=lambda i: (-i[1], i[0], i[2]))

                def cost(item):
                    f, _, _, sec, nbytes = item

                    def c(w):
                        d = sec + fetch
                        if messages and p > 1 and s == "improvement" and w // t != part[f]:
                            d += self.get_cost(nbytes)
                        return d
                    return c
                span, assigned, end = list_schedule([cost(i) for i in order], p * t)
                times[s] += span
                ends = [a + b for a, b in zip(ends, end)]
                if not messages or p == 1:
                    continue
                # Results (fills, improved meshes) back to their owners: each rank's traffic in
                # and out at the bandwidth, pairwise (latency per peer it talks to).
                out_b = [0.0] * p
                in_b = [0.0] * p
                for (f, _, _, _, nbytes), w in zip(order, assigned):
                    r = w // t
                    if r != part[f] and (s == "improvement" or run.by_pattern[f]):
                        out_b[r] += nbytes
                        in_b[part[f]] += nbytes
                move = max(a + b for a, b in zip(out_b, in_b)) / bw + self.comm["allreduce_s"] * levels(p)
                if s == "patterns":  # the expected quads summed over ranks first
                    move += self.allreduce(p) + 8 * run.n / bw
                else:  # the task records gathered, the tasks packed, two window collectives
                    mine = max(sum(i[4] for i in items if part[i[0]] == r) for r in range(p))
                    move += self.allreduce(p) + RECORD_BYTES * len(items) / bw + mine / bw + 2 * self.allreduce(p)
                extra[s] += move
            if s == "improvement" and owner_work:
                # Cutting and merging, or choosing between a face's two passes, on the owners,
                # between and after the rounds.
                per_rank = [0.0] * p
                for f, sec in owner_work.items():
                    per_rank[part[f]] += sec
                times[s] += max(per_rank)
                if messages and p > 1 and improvement[1]:
                    extra[s] += self.allreduce(p)  # whether any face was cut
            if not messages:
                for r in range(p):
                    self.busy[r] += max(ends[r * t:(r + 1) * t])
        return times, extra

    def pattern_seconds(self, f, t):
        """Face f's pattern time on a worker of a rank with t threads (batched_schedule): its move
        search's batches are laid out at once over the rank's threads (PatternFaceOptions::tasks),
        each batch ceil(k / t) layouts long (k the face's mean layouts per batch, each layout the
        search's seconds / layouts); the rest of the face's pattern work is serial. The other
        faces the rank's threads take meanwhile are not modelled (the batches matter where the
        face is the stage's tail, when the other threads are free)."""
        if self.run.threads > 1:  # measured with its batches already split (a replayed 1xT run)
            return self.run.t["patterns"][f]
        return batched_schedule(self.run.t["patterns"][f], self.run.pattern_search[f],
                                self.run.pattern_layouts[f], self.run.pattern_batches[f], t)

    def helped_pattern_seconds(self, p, t, fetch=0.0):
        """Each face's pattern time on p ranks x t threads. With one thread per rank the move
        searches are lent to the ranks done with their faces (PipelineOptions::
        move_layouts_over_ranks): a rank is free once the shared counter has dealt every face and
        its own are done. The faces are dealt as the pipeline deals them (largest first, list
        scheduling); a lendable face's search starts halfway through its serial part, and each
        of its lent batches (lent_batch_seconds) gets the ranks free when it starts, shared
        evenly with the other searches running then. Three rounds of that (the helped times
        change the schedule). A run measured on several ranks or threads already holds its help."""
        run = self.run
        sec = [self.pattern_seconds(f, t) for f in range(run.n)]
        lendable = [f for f in range(run.n) if run.lendable[f] and run.layout_batches[f] > 0
                    and run.layout_seconds[f] > 0 and run.pattern_layouts[f] > 0
                    and run.pattern_batches[f] > 0]
        if t != 1 or p == 1 or run.ranks != 1 or run.threads != 1 or not lendable:
            return sec
        order = sorted(range(run.n), key=lambda f: (-run.expected[f], f))
        cur = list(sec)
        for _ in range(3):
            free = [(0.0, w) for w in range(p)]
            heapq.heapify(free)
            start, end_of = {}, [0.0] * p
            for f in order:
                at, w = heapq.heappop(free)
                start[f] = at
                end_of[w] = at + cur[f] + fetch
                heapq.heappush(free, (end_of[w], w))
            last_dealt = max(start.values(), default=0.0)
            pre = {f: max(0.0, sec[f] - min(run.layout_seconds[f], sec[f])) / 2 for f in lendable}
            window = {f: (start[f] + pre[f], start[f] + cur[f] - pre[f]) for f in lendable}
            new = list(sec)
            for f in lendable:
                layout = min(run.layout_seconds[f], sec[f])
                per = layout / run.pattern_layouts[f]
                nb = run.layout_batches[f]
                steps = run.pattern_batches[f] / nb
                per_step = run.pattern_layouts[f] / run.pattern_batches[f]
                planned = run.layout_vectors[f] / nb
                now = window[f][0]
                for _ in range(nb):
                    helpers = 0
                    if now >= last_dealt:
                        idle = sum(1 for w in range(p) if end_of[w] <= now)
                        searching = sum(1 for g in lendable if window[g][0] <= now < window[g][1])
                        helpers = idle // max(1, searching)
                    now += lent_batch_seconds(per, steps, per_step, planned, helpers + 1)
                new[f] = min(sec[f], sec[f] - layout + (now - window[f][0]))
            cur = new
        return cur

    def improvement_rounds(self):
        """The improvement's tasks, [first round, second round, third round], each task (face,
        order key, piece, seconds, bytes), and the seconds of each cut face's cutting and merging
        (or of the choice between a face's two passes dealt as two tasks). The third round holds
        the cut faces improved whole after their pieces (2k + 2 piece times: the last one)."""
        run = self.run
        first, second, third, owner_work = [], [], [], {}
        for f in range(run.n):
            q = run.improve_quads[f]
            if q <= 0:
                continue
            tasks = run.improve_tasks[f]
            passes = run.improve_passes[f]
            if not tasks and passes:
                # Both passes in the first round, each with the face's input (its bytes); the
                # second passes dealt after every other task, largest first among themselves. A
                # second pass the run skipped (0 s: its first, done before on its rank, did not
                # want it) stays 0 s: where the run would start it before its first ended, its
                # work is missed.
                first.append((f, q, 0, passes[0], run.bytes[f]))
                if len(passes) > 1:
                    first.append((f, q - 1e15, 1, passes[1], run.bytes[f]))
                owner_work[f] = max(0.0, run.t["improvement"][f] - sum(passes))
                continue
            if not tasks:
                first.append((f, q, -1, run.t["improvement"][f], run.bytes[f]))
                continue
            pieces = tasks
            if len(tasks) % 2 == 0:  # the whole face after its pieces
                pieces = tasks[:-1]
                third.append((f, q, len(pieces), tasks[-1], run.bytes[f]))
            k = (len(pieces) - 1) // 2
            for i, sec in enumerate(pieces):
                n = k if i < k else len(pieces) - k
                (first if i < k else second).append((f, q / n, i, sec, run.bytes[f] / n))
            owner_work[f] = max(0.0, run.t["improvement"][f] - sum(tasks))
        return [first, second, third], owner_work

    def predict(self, p, t):
        """{stage: predicted seconds} on p ranks x t threads, in the measured run's stage order."""
        run = self.run
        part = self.partition(p)
        comp = self.compute(p, t)
        dealt, extra = self.dealt(p, t, part, messages=True)
        comp.update(dealt)  # with the counter's and the reads' costs
        bw = self.comm["bandwidth_bytes_per_s"]
        out = {}
        for s, measured in run.seconds.items():
            if s in comp:
                v = comp[s] + self.residual[s] + extra.get(s, 0.0) + self.allreduce(p)
                if s == "sizemap":
                    v += self.allreduce(p)  # the curve sizes' min-reduction
            elif s in GATHER:
                away = sum(b for f, b in enumerate(run.bytes) if part[f] != 0)
                v = measured + away / bw + self.allreduce(p) * 2 + self.comm["allreduce_s"] * (p - 1)
            elif s == "curves" and run.curve_rounds:
                v = self.curves(p, t) + self.allreduce(p)
            elif s == "load" and run.load_rounds:
                v = self.replay_rounds("load", run.load_rounds, p, t) + self.allreduce(p)
            elif s in REPLICATED:
                v = measured + self.allreduce(p)
            else:
                v = measured  # rank 0 after the pipeline (statistics, writing, ...)
            out[s] = v
        return out

    def imbalance(self, p, t):
        """Predicted load imbalance (max / mean of the ranks' busy time, as --stats reports)."""
        self.compute(p, t)
        mean = sum(self.busy) / p
        return max(self.busy) / mean if mean > 0 else 1.0

    def largest_faces(self):
        """The largest face's share of the per-face work, per stage and over the split stages."""
        run = self.run
        res = {}
        for s in PARTITIONED + DEALT:
            tot = sum(run.t[s])
            if tot > 0:
                f = max(range(run.n), key=lambda i: run.t[s][i])
                res[s] = (run.faces[f]["face"], run.t[s][f], run.t[s][f] / tot)
        rounds, _ = self.improvement_rounds()
        tasks = rounds[0] + rounds[1] + rounds[2]
        tot = sum(i[3] for i in tasks)
        if tot > 0:
            big = max(tasks, key=lambda i: i[3])
            res["improvement task"] = (run.faces[big[0]]["face"], big[3], big[3] / tot)
        per_face = [sum(run.t[s][f] for s in PARTITIONED + DEALT) for f in range(run.n)]
        tot = sum(per_face)
        f = max(range(run.n), key=lambda i: per_face[i])
        res["all"] = (run.faces[f]["face"], per_face[f], per_face[f] / tot if tot else 0.0)
        return res

    def bound(self):
        """Time with unlimited ranks: what is not split, plus each split stage's largest face."""
        run = self.run
        v = 0.0
        rounds, owner_work = self.improvement_rounds()
        for s, measured in run.seconds.items():
            if s == "improvement" and (rounds[1] or owner_work):
                # Faces cut into pieces or with their passes as two tasks: each round's largest
                # task, and the cutting and merging or the choice between the passes.
                v += (max((i[3] for i in rounds[0]), default=0.0)
                      + max((i[3] for i in rounds[1]), default=0.0)
                      + max((i[3] for i in rounds[2]), default=0.0)
                      + max(owner_work.values(), default=0.0) + self.residual[s])
            elif s in PARTITIONED or s in DEALT:
                v += max(run.t[s]) + self.residual[s]
            elif s == "curves" and run.curve_rounds:
                # Each round's largest curve, the rest as measured (no messages counted).
                v += measured + sum(max(r["item_seconds"], default=0.0)
                                    - self.curve_round(r, run.ranks, run.threads)
                                    for r in run.curve_rounds)
            elif s == "load" and run.load_rounds:
                v += measured + sum(max(r["item_seconds"], default=0.0)
                                    - self.curve_round(r, run.ranks, run.threads)
                                    for r in run.load_rounds)
            else:
                v += measured
        return v


def parse_config(text):
    text = text.strip()
    if "x" in text:
        p, t = text.split("x", 1)
    else:
        p, t = text, "1"
    if not (p.isdigit() and t.isdigit()) or int(p) < 1 or int(t) < 1:
        raise InputError(f"configuration '{text}' is not P or PxT (ranks x threads)")
    return int(p), int(t)


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f"cannot read {path}: {e}")


def main(argv):
    ap = argparse.ArgumentParser(prog="simulate_scaling.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("stats", help="--stats JSON of a run on one rank (quad stages)")
    ap.add_argument("--configs", required=True, help="comma-separated P or PxT")
    ap.add_argument("--partitions", help="JSON of qsmesh info --json --partition P,...")
    ap.add_argument("--comm", help="JSON of scripts/mpi_costs.c (latencies, bandwidth)")
    ap.add_argument("--real", action="append", default=[], metavar="PxT=STATS.json",
                    help="a real run to compare with (its --stats); repeatable")
    ap.add_argument("--csv", help="write the predictions as CSV (one row per configuration)")
    args = ap.parse_args(argv)
    try:
        run = Run(load_json(args.stats), args.stats)
        partitions = load_json(args.partitions).get("partitions", {}) if args.partitions else {}
        comm = load_json(args.comm) if args.comm else None
        configs = [parse_config(c) for c in args.configs.split(",") if c.strip()]
        reals = {}
        for item in args.real:
            if "=" not in item:
                raise InputError(f"--real: '{item}' is not PxT=STATS.json")
            c, path = item.split("=", 1)
            reals[parse_config(c)] = load_json(path)
        for c in reals:
            if c not in configs:
                configs.append(c)
        configs.sort(key=lambda c: (c[0] * c[1], c[1]))
        sim = Simulator(run, partitions, comm)
    except InputError as e:
        print(f"{TOOL}: {e}", file=sys.stderr)
        return 2

    base_cores = run.threads
    base = (1, run.threads)
    stages = list(run.seconds)
    preds = {c: sim.predict(*c) for c in configs}
    kind = {s: ("split by curve" if s == "curves" and run.curve_rounds
                else "areas split by face" if s == "load" and run.load_rounds
                else "replicated" if s in REPLICATED else "METIS partition" if s in PARTITIONED
                else "dealt" if s in DEALT else "gather on rank 0" if s in GATHER else "rank 0")
            for s in stages}
    labels = [f"{p}x{t}" for p, t in configs]
    print(f"base run: {args.stats} (1x{run.threads}, {run.n} faces, total {run.total:.2f} s)")
    print(f"partition: {'METIS (qsmesh info --partition)' if partitions else 'greedy'}"
          + (f"; greedy for {sorted(sim.greedy)} ranks (not in --partitions)" if partitions and sim.greedy else ""))
    print("messages: " + ", ".join(f"{k} {v:.3g}" for k, v in sim.comm.items()))
    print()
    print("| stage | kind | measured 1x%d s | " % run.threads + " | ".join(f"{l} s" for l in labels) + " |")
    print("|---|---|---|" + "---|" * len(labels))
    for s in stages:
        print(f"| {s} | {kind[s]} | {run.seconds[s]:.3f} | "
              + " | ".join(f"{preds[c][s]:.3f}" for c in configs) + " |")
    totals = {c: sum(preds[c].values()) for c in configs}
    base_total = sum(run.seconds.values())
    print(f"| **total** | | {base_total:.3f} | " + " | ".join(f"**{totals[c]:.3f}**" for c in configs) + " |")
    print(f"| speedup | | 1.00 | " + " | ".join(f"{base_total / totals[c]:.2f}" for c in configs) + " |")
    print(f"| efficiency | | 1.00 | " + " | ".join(
        f"{base_total / totals[c] * base_cores / (c[0] * c[1]):.2f}" for c in configs) + " |")
    # Per-stage speedups of the split stages.
    print()
    print("| stage speedup | " + " | ".join(labels) + " |")
    print("|---|" + "---|" * len(labels))
    for s in stages:
        if s in PARTITIONED or s in DEALT:
            print(f"| {s} | " + " | ".join(
                f"{run.seconds[s] / preds[c][s]:.2f}" if preds[c][s] > 0 else "-" for c in configs) + " |")

    big = sim.largest_faces()
    print()
    print("largest face per stage (face, seconds, share of the stage's per-face work):")
    for s, (f, sec, share) in big.items():
        print(f"  {s}: face {f}, {sec:.3f} s, {share:.4f} (1/{1 / share:.1f})" if share > 0 else f"  {s}: -")
    b = sim.bound()
    print(f"unlimited ranks (each split stage takes its largest face): {b:.3f} s, speedup "
          f"{base_total / b:.2f}")

    status = 0
    replayed = {}
    for c, st in reals.items():
        # The same rules on the real run's own per-face times and partition (face_stats' rank):
        # what is left of the error is the per-face times' change between the runs.
        try:
            rr = Run(st, f"{c[0]}x{c[1]}", any_ranks=True)
        except InputError:
            continue
        if rr.n != run.n:
            continue
        rs = Simulator(rr, {str(c[0]): rr.face_rank}, sim.comm, sim.residual)
        replayed[c] = sum(rs.predict(*c).values())
    if reals:
        print()
        print("| config | real total s | predicted s | error | replayed s | error | load imbalance real / predicted | " + " | ".join(
            f"{s} real / predicted" for s in stages if s in PARTITIONED or s in DEALT) + " |")
        print("|---|---|---|---|---|---|---|" + "---|" * sum(1 for s in stages if s in PARTITIONED or s in DEALT))
        for c, st in reals.items():
            real_total = st["seconds"].get("total", 0.0)
            pred = totals[c]
            err = (pred - real_total) / real_total if real_total > 0 else float("nan")
            cells = []
            for s in stages:
                if s in PARTITIONED or s in DEALT:
                    cells.append(f"{st['seconds'].get(s, 0.0):.2f} / {preds[c][s]:.2f}")
            imb = f"{st.get('load_imbalance', 1.0):.2f} / {sim.imbalance(*c):.2f}"
            rep = replayed.get(c)
            rep_cells = (f"{rep:.2f} | {100 * (rep - real_total) / real_total:+.1f}%" if rep and real_total > 0
                         else "- | -")
            print(f"| {c[0]}x{c[1]} | {real_total:.2f} | {pred:.2f} | {100 * err:+.1f}% | {rep_cells} | {imb} | "
                  + " | ".join(cells) + " |")
    if args.csv:
        with open(args.csv, "w") as f:
            f.write("ranks x threads,cores,predicted s,predicted speedup,ideal speedup,efficiency,"
                    "unlimited ranks speedup\n")
            f.write(f"1x{run.threads},{run.threads},{base_total:.3f},1.00,1.00,1.00,{base_total / b:.2f}\n")
            for c in configs:
                if c == base:
                    continue
                n = c[0] * c[1]
                f.write(f"{c[0]}x{c[1]},{n},{totals[c]:.3f},{base_total / totals[c]:.2f},"
                        f"{n / base_cores:.2f},{base_total / totals[c] * base_cores / n:.2f},"
                        f"{base_total / b:.2f}\n")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
