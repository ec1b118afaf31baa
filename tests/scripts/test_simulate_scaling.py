#!/usr/bin/env python3
"""ctest: the scheduling rules of scripts/simulate_scaling.py on small cases worked out by hand
(list scheduling in the given order, not an optimal schedule; METIS-partitioned stages as the
slowest rank's threads; dealt stages largest first over all ranks' threads; the measured run
reproduced on its own configuration), and its refusals.
Usage: test_simulate_scaling.py SCRIPTS_DIR"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.dont_write_bytecode = True
SCRIPTS = sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "../../scripts")
sys.path.insert(0, SCRIPTS)
import simulate_scaling as sim  # noqa: E402

NO_COMM = {"allreduce_s": 1e-30, "fetch_and_add_s": 1e-30, "get_64k_s": 1e-30,
           "bandwidth_bytes_per_s": 1e30}


def stats(faces, seconds, ranks=1, threads=1):
    """A --stats object: faces as (background, patterns, unstructured, improvement, expected,
    improvement_quads)."""
    fs = []
    for i, (bg, pat, un, imp, exp, iq) in enumerate(faces):
        fs.append({"face": i, "rank": 0, "method": "unstructured",
                   "stage_seconds": {"background": bg, "crossfield": 0.0, "sizemap": 0.0,
                                     "patterns": pat, "unstructured": un, "improvement": imp,
                                     "pattern_compare": 0.0, "expected_quads": exp,
                                     "improvement_quads": iq, "bytes": 1000}})
    return {"ranks": ranks, "threads": threads, "seconds": dict(seconds, total=sum(seconds.values())),
            "face_stats": fs}


class ListScheduling(unittest.TestCase):
    def test_greedy_not_optimal(self):
        # 5,4 then 3,3,3 on two workers: the greedy rule gives 5+3 | 4+3+3 = 10 (the optimum, 9,
        # pairs 5+4 against 3+3+3); the pipeline's counter is greedy, so must be the simulation.
        span, assigned, _ = sim.list_schedule([5, 4, 3, 3, 3], 2)
        self.assertEqual(span, 10)
        self.assertEqual(assigned, [0, 1, 1, 0, 1])

    def test_order_matters(self):
        # Face order (TBB over a rank's faces) vs largest first.
        self.assertEqual(sim.list_schedule([1, 1, 1, 1, 4], 2)[0], 6)
        self.assertEqual(sim.list_schedule([4, 1, 1, 1, 1], 2)[0], 4)

    def test_cost_depends_on_worker(self):
        # Worker 1 pays 10 for any item: the second item waits for worker 0 only if that is sooner.
        cost = lambda w: 1 + (10 if w == 1 else 0)  # noqa: E731
        span, assigned, _ = sim.list_schedule([cost, cost, cost], 2)
        self.assertEqual(assigned, [0, 1, 0])
        self.assertEqual(span, 11)

    def test_greedy_partition(self):
        # 5 -> part 0, 4 -> 1, 2 -> 1 (4 < 5), 1 -> 0 (5 < 6).
        self.assertEqual(sim.greedy_partition([1, 5, 4, 2], 2), [0, 0, 1, 1])


class Stages(unittest.TestCase):
    def setUp(self):
        # Four faces; the background stage 1+2+3+4 = 10 s, 0.5 s of it outside the faces; patterns
        # 0.1 each; improvement on faces 0-2 only.
        self.faces = [(1, 0.1, 1, 1, 10, 50), (2, 0.1, 1, 1, 40, 30), (3, 0.1, 1, 4, 30, 100),
                      (4, 0.1, 1, 0, 20, 0)]
        self.seconds = {"load": 1.0, "background": 10.5, "patterns": 0.4, "unstructured": 4.0,
                        "improvement": 6.0, "assemble": 0.2, "write": 0.3}
        self.run = sim.Run(stats(self.faces, self.seconds))

    def test_base_configuration_is_reproduced(self):
        s = sim.Simulator(self.run, comm=NO_COMM)
        pred = s.predict(1, 1)
        for k, v in self.seconds.items():
            self.assertAlmostEqual(pred[k], v, places=6, msg=k)
        self.assertAlmostEqual(s.residual["background"], 0.5)

    def test_partitioned_stage_is_the_slowest_rank(self):
        # Ranks {0, 3} and {1, 2}: background 1+4 = 5 and 2+3 = 5; with {0, 1} / {2, 3}: 3 and 7.
        for part, expect in (([0, 1, 1, 0], 5.0), ([0, 0, 1, 1], 7.0)):
            s = sim.Simulator(self.run, partitions={"2": part}, comm=NO_COMM)
            self.assertAlmostEqual(s.predict(2, 1)["background"], expect + 0.5, places=6)
        # Two threads on one rank: faces in order 1,2 | 3 (at 1), 4 (at 2) -> 1+3=4, 2+4=6.
        s = sim.Simulator(self.run, comm=NO_COMM)
        self.assertAlmostEqual(s.predict(1, 2)["background"], 6.5, places=6)

    def test_dealt_stage_largest_first(self):
        # Improvement order by improvement_quads: 4 s (face 2), then faces 0 and 1 (1 s each): on
        # two workers 4 | 1+1 -> 4 s (in face order it would be 1+4 | 1 -> 5 s), plus the 0 s
        # measured outside the faces (6 - 6).
        s = sim.Simulator(self.run, partitions={"2": [0, 0, 1, 1], "3": [0, 1, 2, 2]}, comm=NO_COMM)
        self.assertAlmostEqual(s.predict(2, 1)["improvement"], 4.0, places=6)
        self.assertAlmostEqual(s.predict(1, 2)["improvement"], 4.0, places=6)
        self.assertAlmostEqual(s.predict(3, 1)["improvement"], 4.0, places=6)
        # Patterns by expected quads: 4 faces of 0.1 on 3 workers -> 0.2.
        self.assertAlmostEqual(s.predict(3, 1)["patterns"], 0.2, places=6)

    def test_imbalance(self):
        # Ranks {0, 1} / {2, 3}: background 3 | 7, patterns (dealt by expected quads 40, 30, 20,
        # 10: faces 1, 2, 3, 0) 0.2 | 0.2, unstructured 2 | 2, improvement (face 2 to rank 0, then
        # faces 0 and 1 to rank 1) 4 | 2: busy 9.2 | 11.2, max / mean = 11.2 / 10.2.
        s = sim.Simulator(self.run, partitions={"2": [0, 0, 1, 1]}, comm=NO_COMM)
        self.assertAlmostEqual(s.imbalance(2, 1), 11.2 / 10.2, places=6)
        self.assertAlmostEqual(s.imbalance(1, 2), 1.0)

    def test_messages_cost_time(self):
        comm = dict(NO_COMM, fetch_and_add_s=0.01, allreduce_s=0.001)
        s = sim.Simulator(self.run, partitions={"2": [0, 0, 1, 1]}, comm=comm)
        free = sim.Simulator(self.run, partitions={"2": [0, 0, 1, 1]}, comm=NO_COMM)
        self.assertGreater(s.predict(2, 1)["improvement"], free.predict(2, 1)["improvement"] + 0.01)
        self.assertGreater(s.predict(2, 1)["load"], free.predict(2, 1)["load"])

    def test_largest_face_and_bound(self):
        s = sim.Simulator(self.run, comm=NO_COMM)
        big = s.largest_faces()
        self.assertEqual(big["improvement"][0], 2)
        self.assertAlmostEqual(big["improvement"][2], 4 / 6)
        # Unlimited ranks: load 1 + background 4+0.5 + patterns 0.1+0 + unstructured 1+0 +
        # improvement 4+0 + assemble 0.2 + write 0.3.
        self.assertAlmostEqual(s.bound(), 11.1, places=6)


class Distance(unittest.TestCase):
    def test_distance_is_partitioned(self):
        # The distance stage (pipeline's, before the gather) goes by the METIS partition like the
        # background: faces 1, 2, 3, 4 s on ranks {0, 3} / {1, 2} -> 5 s, + 0.5 s outside them.
        st = stats([(0, 0, 0, 0, 1, 0)] * 4, {"distance": 10.5})
        for i, f in enumerate(st["face_stats"]):
            f["stage_seconds"]["distance"] = float(i + 1)
        s = sim.Simulator(sim.Run(st), partitions={"2": [0, 1, 1, 0]}, comm=NO_COMM)
        self.assertAlmostEqual(s.predict(2, 1)["distance"], 5.5, places=6)
        self.assertAlmostEqual(s.predict(1, 1)["distance"], 10.5, places=6)


class Batches(unittest.TestCase):
    def test_batched_schedule(self):
        # 10 s of which 8 s search: 8 layouts of 1 s in 2 batches of 4. One thread: serial; two:
        # 2 + 2 batches x 2 layouts; four or more: 2 + 2 x 1; never above the serial time.
        self.assertAlmostEqual(sim.batched_schedule(10, 8, 8, 2, 1), 10)
        self.assertAlmostEqual(sim.batched_schedule(10, 8, 8, 2, 2), 6)
        self.assertAlmostEqual(sim.batched_schedule(10, 8, 8, 2, 4), 4)
        self.assertAlmostEqual(sim.batched_schedule(10, 8, 8, 2, 64), 4)
        self.assertAlmostEqual(sim.batched_schedule(10, 8, 8, 8, 4), 10)  # one layout a batch
        self.assertAlmostEqual(sim.batched_schedule(10, 0, 0, 0, 4), 10)  # no search

    def test_pattern_stage_uses_the_rank_threads(self):
        # One face, patterns 10 s, 8 of them the search (8 layouts, 2 batches): 1x4 takes 4 s, 4x1
        # still 10 s (the batches stay on the face's rank).
        st = stats([(0, 10, 0, 0, 5, 0)], {"patterns": 10.0})
        ss = st["face_stats"][0]["stage_seconds"]
        ss.update(pattern_layouts=8, pattern_batches=2, pattern_search=8.0)
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        self.assertAlmostEqual(s.predict(1, 4)["patterns"], 4.0, places=6)
        self.assertAlmostEqual(s.predict(4, 1)["patterns"], 10.0, places=6)
        # A run on two threads measured its face with the batches split already: replayed as is.
        st2 = stats([(0, 6, 0, 0, 5, 0)], {"patterns": 6.0}, threads=2)
        st2["face_stats"][0]["stage_seconds"].update(pattern_layouts=8, pattern_batches=2,
                                                     pattern_search=4.0)
        s2 = sim.Simulator(sim.Run(st2), comm=NO_COMM)
        self.assertAlmostEqual(s2.predict(1, 2)["patterns"], 6.0, places=6)


class Helped(unittest.TestCase):
    def test_helped_schedule(self):
        # 10 s of which 8 s laying out 8 layouts (1 s each), read in 4 single steps of 2, planned
        # in 2 lent batches of 8. No helper: serial; one: 2 + 4 (a layout per worker per step);
        # seven or more: 2 + 2 (one layout per lent batch); never above the serial time.
        self.assertAlmostEqual(sim.helped_schedule(10, 8, 8, 4, 2, 16, 0), 10)
        self.assertAlmostEqual(sim.helped_schedule(10, 8, 8, 4, 2, 16, 1), 6)
        self.assertAlmostEqual(sim.helped_schedule(10, 8, 8, 4, 2, 16, 7), 4)
        self.assertAlmostEqual(sim.helped_schedule(10, 8, 8, 4, 2, 16, 100), 4)
        self.assertAlmostEqual(sim.helped_schedule(10, 8, 8, 8, 8, 8, 7), 10)  # one layout a step
        self.assertAlmostEqual(sim.helped_schedule(10, 0, 0, 0, 0, 0, 7), 10)  # no search

    def test_pattern_stage_lends_to_free_ranks(self):
        # Face 0: patterns 10 s, 8 of them its 8 layouts (4 steps of 2, 2 lent batches of 8);
        # eight faces of 0.1 s. 9x1: the eight others free by the search (at 1 s): 2 + 2 x 1 = 4 s.
        # 4x1 or 2x1 (one to three ranks free): a layout per step, 2 + 4 = 6 s. Not lendable: 10 s.
        faces = [(0, 10, 0, 0, 50, 0)] + [(0, 0.1, 0, 0, 9 - i, 0) for i in range(8)]
        st = stats(faces, {"patterns": 10.8})
        st["face_stats"][0]["stage_seconds"].update(
            pattern_layouts=8, pattern_batches=4, pattern_search=8.5, pattern_layout_seconds=8.0,
            pattern_layout_batches=2, pattern_layout_vectors=16, pattern_vector_lendable=1)
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        self.assertAlmostEqual(s.predict(1, 1)["patterns"], 10.8, places=6)
        self.assertAlmostEqual(s.predict(9, 1)["patterns"], 4.0, places=6)
        self.assertAlmostEqual(s.predict(4, 1)["patterns"], 6.0, places=6)
        self.assertAlmostEqual(s.predict(2, 1)["patterns"], 6.0, places=6)
        st["face_stats"][0]["stage_seconds"]["pattern_vector_lendable"] = 0
        s0 = sim.Simulator(sim.Run(st), comm=NO_COMM)
        self.assertAlmostEqual(s0.predict(4, 1)["patterns"], 10.0, places=6)

    def test_no_rank_is_free_while_faces_are_dealt(self):
        # Two ranks, the lendable face first and nine faces of 1 s: the other rank takes faces
        # until 9 s, after the search's midpoint (1 s): no help, 10 s.
        faces = [(0, 10, 0, 0, 50, 0)] + [(0, 1.0, 0, 0, 10 - i, 0) for i in range(9)]
        st = stats(faces, {"patterns": 19.0})
        st["face_stats"][0]["stage_seconds"].update(
            pattern_layouts=8, pattern_batches=4, pattern_search=8.5, pattern_layout_seconds=8.0,
            pattern_layout_batches=2, pattern_layout_vectors=16, pattern_vector_lendable=1)
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        self.assertAlmostEqual(s.predict(2, 1)["patterns"], 10.0, places=6)


class Pieces(unittest.TestCase):
    def test_pieces_are_tasks_in_two_rounds(self):
        # Face 0 (3000 quads) improved in pieces: 3 of 2 s in the first round, 4 of 1 s in the
        # second, 1 s of cutting and merging on its owner (11 - 10); face 1 (500 quads) whole, 1 s.
        st = stats([(1, 0, 0, 11, 1, 3000), (1, 0, 0, 1, 1, 500)],
                   {"background": 2.0, "improvement": 12.0})
        st["face_stats"][0]["stage_seconds"]["improvement_tasks"] = [2, 2, 2, 1, 1, 1, 1]
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        # Three workers: round 1 2 | 2 | 2+1 -> 3, round 2 1+1 | 1 | 1 -> 2, then 1 on the owner.
        self.assertAlmostEqual(s.predict(3, 1)["improvement"], 6.0, places=6)
        # One worker: everything in turn.
        self.assertAlmostEqual(s.predict(1, 1)["improvement"], 12.0, places=6)
        big = s.largest_faces()
        self.assertEqual(big["improvement task"][0], 0)
        self.assertAlmostEqual(big["improvement task"][1], 2.0)
        # Unlimited ranks: background 1 + improvement 2 + 1 + 1.
        self.assertAlmostEqual(s.bound(), 5.0, places=6)

    def test_two_passes_are_two_tasks_of_the_first_round(self):
        # Face 0 (3000 quads): its passes as two tasks of 3 s and 2 s, 0.5 s of choosing on its
        # owner (5.5 - 5); face 1 (500 quads) whole, 1 s.
        st = stats([(1, 0, 0, 5.5, 1, 3000), (1, 0, 0, 1, 1, 500)],
                   {"background": 2.0, "improvement": 6.5})
        st["face_stats"][0]["stage_seconds"]["improvement_passes"] = [3, 2]
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        # Two workers: the first pass (3) | face 1 (1) then the second pass (2, dealt last) -> 3,
        # then 0.5 on the owner.
        self.assertAlmostEqual(s.predict(2, 1)["improvement"], 3.5, places=6)
        # Three workers: 3 | 1 | 2.
        self.assertAlmostEqual(s.predict(3, 1)["improvement"], 3.5, places=6)
        self.assertAlmostEqual(s.predict(1, 1)["improvement"], 6.5, places=6)
        big = s.largest_faces()
        self.assertAlmostEqual(big["improvement task"][1], 3.0)
        # Unlimited ranks: background 1 + improvement 3 + 0.5.
        self.assertAlmostEqual(s.bound(), 4.5, places=6)


class Curves(unittest.TestCase):
    def test_curves_split_by_curve(self):
        # One round: weights 1, 5, 3, 3, 2 (the deal of C++ test
        # Partition.DealByWeightIsGreedyLongestFirst: ranks 1, 0, 1, 1, 0), curves 0.1, 0.5, 0.3,
        # 0.3, 0.2 s; the stage 2 s, 0.6 s of it outside the round's curves.
        st = stats([(1, 0, 0, 0, 1, 0)], {"load": 1.0, "curves": 2.0, "background": 1.0})
        st["curve_rounds"] = [{"seconds": 1.5, "bytes": 1000, "weights": [1, 5, 3, 3, 2],
                               "curve_seconds": [0.1, 0.5, 0.3, 0.3, 0.2]}]
        self.assertEqual(sim.greedy_partition([1, 5, 3, 3, 2], 2), [1, 0, 1, 1, 0])
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        self.assertAlmostEqual(s.predict(1, 1)["curves"], 2.0, places=6)
        # 2x1: ranks 0.5 + 0.2 | 0.1 + 0.3 + 0.3 -> 0.7; 1x2: 0.1, 0.5 | 0.3 -> 0.4, 0.3 -> 0.7
        # (0.4 < 0.5), 0.2 -> 0.7.
        self.assertAlmostEqual(s.predict(2, 1)["curves"], 1.3, places=6)
        self.assertAlmostEqual(s.predict(1, 2)["curves"], 1.3, places=6)
        # Five or more ranks: the largest curve.
        self.assertAlmostEqual(s.predict(64, 1)["curves"], 1.1, places=6)
        # The all-gather: the bytes three times at the bandwidth.
        slow = sim.Simulator(sim.Run(st), comm=dict(NO_COMM, bandwidth_bytes_per_s=1e4))
        self.assertAlmostEqual(slow.predict(2, 1)["curves"], 1.3 + 0.3, places=6)
        self.assertAlmostEqual(slow.predict(1, 1)["curves"], 2.0, places=6)
        # Unlimited ranks: the curves stage takes its largest curve.
        self.assertAlmostEqual(s.bound(), 1.0 + 1.1 + 1.0, places=6)
        # A run without rounds keeps the stage replicated.
        del st["curve_rounds"]
        self.assertAlmostEqual(sim.Simulator(sim.Run(st), comm=NO_COMM).predict(64, 1)["curves"],
                               2.0, places=6)


class Load(unittest.TestCase):
    def test_face_areas_split_by_face(self):
        # The load's round: four faces of equal weight (dealt 0, 1, 0, 1 over 2 ranks), areas
        # 0.2, 0.2, 0.1, 0.1 s; the stage 1 s, 0.4 s of it the file's reading on every rank.
        st = stats([(1, 0, 0, 0, 1, 0)], {"load": 1.0, "background": 1.0})
        st["load_rounds"] = [{"seconds": 0.6, "bytes": 64, "weights": [1, 1, 1, 1],
                              "item_seconds": [0.2, 0.2, 0.1, 0.1]}]
        self.assertEqual(sim.greedy_partition([1, 1, 1, 1], 2), [0, 1, 0, 1])
        s = sim.Simulator(sim.Run(st), comm=NO_COMM)
        self.assertAlmostEqual(s.predict(1, 1)["load"], 1.0, places=6)
        self.assertAlmostEqual(s.predict(2, 1)["load"], 0.7, places=6)
        self.assertAlmostEqual(s.predict(1, 2)["load"], 0.7, places=6)
        self.assertAlmostEqual(s.predict(64, 1)["load"], 0.6, places=6)
        # A run without load rounds keeps the load replicated.
        del st["load_rounds"]
        self.assertAlmostEqual(sim.Simulator(sim.Run(st), comm=NO_COMM).predict(64, 1)["load"],
                               1.0, places=6)


class CommandLine(unittest.TestCase):
    def test_refusals_and_output(self):
        script = os.path.join(SCRIPTS, "simulate_scaling.py")
        with tempfile.TemporaryDirectory() as d:
            two = os.path.join(d, "two.json")
            with open(two, "w") as f:
                json.dump(stats([(1, 0, 0, 0, 1, 0)], {"background": 1.0}, ranks=2), f)
            r = subprocess.run([sys.executable, script, two, "--configs", "2"], capture_output=True,
                               text=True)
            self.assertEqual(r.returncode, 2)
            self.assertIn("one rank", r.stderr)
            one = os.path.join(d, "one.json")
            with open(one, "w") as f:
                json.dump(stats([(1, 0, 0, 0, 1, 0), (1, 0, 0, 0, 1, 0)], {"background": 2.0}), f)
            r = subprocess.run([sys.executable, script, one, "--configs", "2,3x",
                                "--csv", os.path.join(d, "t.csv")], capture_output=True, text=True)
            self.assertEqual(r.returncode, 2)
            self.assertIn("3x", r.stderr)
            r = subprocess.run([sys.executable, script, one, "--configs", "2", "--real",
                                "2x1=" + one, "--csv", os.path.join(d, "t.csv")],
                               capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("| 2x1 | 2.00 |", r.stdout)
            with open(os.path.join(d, "t.csv")) as f:
                rows = f.read().splitlines()
            self.assertEqual(len(rows), 3)
            self.assertTrue(rows[2].startswith("2x1,2,"))


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
