#!/usr/bin/python3
"""scripts/compare_results.py: the run's measurements (whole keys such as `date`, `setup_seconds`)
are ignored, every result is compared, including keys that merely contain a volatile word
(`updates`, `steps_per_update` contain "date")."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "compare_results.py")


def compare(before, after):
    with tempfile.TemporaryDirectory() as d:
        paths = []
        for name, doc in (("before.json", before), ("after.json", after)):
            paths.append(os.path.join(d, name))
            with open(paths[-1], "w") as f:
                json.dump(doc, f)
        r = subprocess.run([sys.executable, SCRIPT, *paths], capture_output=True, text=True)
        return r.returncode, r.stdout


def case(**kw):
    c = {"max_error_mm": 0.25, "updates": 40, "steps_per_update": 3, "setup_seconds": 1.0,
         "solve_seconds": 2.0, "memory_mib": 10.0, "peak_memory_mb_per_rank": 5.0,
         "seconds_per_update": 0.1, "update_ms": 3.0,
         "timing_provenance": {"source": "measured", "measured_at": "2026-01-01T00:00:00Z"}}
    c.update(kw)
    return {"date": "2026-01-01", "command": "run a", "machine": {"cores": 2},
            "scenes": [{"outcomes": [c]}]}


class CompareResults(unittest.TestCase):
    def test_identical_results_agree(self):
        self.assertEqual(compare(case(), case())[0], 0)

    def test_measurements_of_the_run_are_ignored(self):
        after = case(setup_seconds=9.0, solve_seconds=8.0, memory_mib=99.0,
                     peak_memory_mb_per_rank=50.0, seconds_per_update=0.7, update_ms=30.0,
                     timing_provenance={"source": "cache", "measured_at": "2027-01-01"})
        after["date"], after["command"], after["machine"] = "2027-02-02", "run b", {"cores": 64}
        self.assertEqual(compare(case(), after)[0], 0)

    def test_updates_are_compared(self):
        code, out = compare(case(), case(updates=41))
        self.assertEqual(code, 1)
        self.assertIn("/updates: 40 before, 41 after", out)

    def test_steps_per_update_are_compared(self):
        code, out = compare(case(), case(steps_per_update=4))
        self.assertEqual(code, 1)
        self.assertIn("/steps_per_update: 3 before, 4 after", out)

    def test_a_result_beyond_rtol_is_reported(self):
        code, out = compare(case(), case(max_error_mm=0.25 * (1 + 1e-6)))
        self.assertEqual(code, 1)
        self.assertIn("max_error_mm", out)


if __name__ == "__main__":
    unittest.main()
