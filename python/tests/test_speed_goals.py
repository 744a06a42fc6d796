"""python/bench/speed_goals.py: its reading of Google Benchmark's reports, its ratios and its output file.

The benchmarks themselves are measurements and run outside the suite; here one real report of a fast
benchmark checks that the reading matches what the perf programs write."""
import importlib.util
import json
import os

import pytest


@pytest.fixture(scope="module")
def goals(source_dir):
    spec = importlib.util.spec_from_file_location("speed_goals",
                                                  os.path.join(source_dir, "python", "bench", "speed_goals.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(name, ms, aggregate=None):
    """One entry of a report as Google Benchmark writes it (perf_common.hpp's process_time/real_time suffixes)."""
    entry = {"name": name + "/process_time/real_time" + ("_" + aggregate if aggregate else ""),
             "run_name": name + "/process_time/real_time", "run_type": "aggregate" if aggregate else "iteration",
             "real_time": ms, "time_unit": "ms"}
    if aggregate:
        entry["aggregate_name"] = aggregate
    return entry


def report(times):
    """A report with repetitions: each benchmark's runs and its aggregates (the median between the runs)."""
    entries = []
    for name, ms in times.items():
        entries += [run(name, ms * 0.9), run(name, ms * 1.3), run(name, ms), run(name, ms * 1.07, "mean"),
                    run(name, ms, "median"), run(name, ms * 0.2, "stddev")]
    return {"benchmarks": entries}


PATH_TIMES = {"colorJitter": 10.0, "colorJitterTukeyRead": 19.0, "colorJitterPoisson": 45.0, "randomScene": 52.0,
              "standardNormals": 5.0}


def path_report(paths):
    times = {"BM_Augment_%s/%s" % (what, p): ms for p in paths for what, ms in PATH_TIMES.items()}
    times.update({"BM_BurstStatistics_rawgment/%s/8/6" % p: 300.0 for p in paths})
    times["BM_BurstStatistics_memcpy"] = 100.0
    times["BM_Augment_philoxWords/avx2"] = 4.0
    return report(times)


def test_medians_are_the_median_aggregates_and_names_lose_the_harness_suffixes(goals):
    times = goals.median_times(report({"BM_Augment_colorJitter/avx2": 14.8}))
    assert times == {"BM_Augment_colorJitter/avx2": 14.8}
    # Without repetitions: the runs themselves, their /iterations:N suffix dropped, the middle one kept.
    single = {"benchmarks": [dict(run("BM_BurstStatistics_memcpy/iterations:3", ms), time_unit="us")
                             for ms in (230e3, 210e3, 250e3)]}
    assert goals.median_times(single) == {"BM_BurstStatistics_memcpy": pytest.approx(230.0)}


def test_every_goal_is_the_ratio_of_its_own_path_and_judged_against_its_target(goals):
    times = goals.median_times(path_report(["baseline", "avx2"]))
    paths, rows = goals.goal_rows(times, cores=2)
    assert paths == ["baseline", "avx2"]
    by_goal = {goal.split(".")[0]: (target, cells) for goal, target, cells in rows}
    assert by_goal["1"][1]["avx2"] == ("1.90x", True)
    assert by_goal["2"][1]["baseline"] == ("4.50x", False)
    assert by_goal["3"][1]["avx2"] == ("3.00x", True)
    assert by_goal["4"][1]["avx2"] == ("5.20x", False)
    # 12 M normals in 5 ms on 2 cores: 1.2 G per core.
    assert by_goal["5"][1]["avx2"] == ("1.20 G", True)
    assert goals.philox_row(times, cores=2) == {"avx2": pytest.approx(1.5)}
    table = goals.markdown("a host", paths, rows, goals.philox_row(times, 2), None)
    assert "| 2. POISSON shot draws / jitter | at most 4x | 4.50x | 4.50x | no |" in table
    assert "| 1. Tukey-lambda read noise / jitter | at most 2x | 1.90x | 1.90x | yes |" in table


def test_a_missing_benchmark_is_named(goals):
    times = goals.median_times(path_report(["avx2"]))
    del times["BM_Augment_randomScene/avx2"]
    with pytest.raises(goals.MissingBenchmark, match="BM_Augment_randomScene/avx2"):
        goals.goal_rows(times, cores=2)


def test_a_real_report_of_the_perf_program_is_read(goals, tmp_path):
    binary = os.path.join(os.environ.get("RAWGMENT_BUILD_DIR", ""), "bin", "perf_augment")
    if not os.access(binary, os.X_OK):
        pytest.skip("perf_augment is not built here (RAWGMENT_BUILD_PERF=OFF, as in the sanitizer build)")
    times = goals.run_benchmarks(binary, "BM_Augment_memcpy", 2)
    assert list(times) == ["BM_Augment_memcpy"]
    assert 0 < times["BM_Augment_memcpy"] < 1000  # a 24 MB copy: milliseconds, whatever the host


def test_a_failed_run_leaves_the_previous_table_and_unknown_flags_are_refused(goals, tmp_path, capsys):
    out = tmp_path / "goals.md"
    out.write_text("the previous table\n")
    with pytest.raises(FileNotFoundError, match="perf_augment"):
        goals.main(["--build", str(tmp_path / "no_build"), "--out", str(out), "--replace"])
    assert out.read_text() == "the previous table\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["goals.md"]  # no temporary left
    with pytest.raises(SystemExit):
        goals.main(["--repetition", "3"])
    assert "--repetition" in capsys.readouterr().err
    with pytest.raises(FileExistsError):
        goals.write_atomically(str(out), "a new table\n")
    assert out.read_text() == "the previous table\n"
    goals.write_atomically(str(out), "a new table\n", replace=True)
    assert out.read_text() == "a new table\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["goals.md"]


def test_an_out_that_exists_or_has_no_folder_is_refused_before_the_benchmarks(goals, tmp_path, capsys):
    # The build folder does not exist either: an error about --out proves it came first.
    out = tmp_path / "goals.md"
    out.write_text("the previous table\n")
    for argv, message in (([], "exists; it is not replaced without --replace"),
                          (["--out", str(tmp_path / "missing" / "goals.md")], "does not exist"),
                          (["--out", str(tmp_path)], "is a folder")):
        with pytest.raises(SystemExit) as stop:
            goals.main(["--build", str(tmp_path / "no_build"), "--out", str(out), *argv])
        assert stop.value.code == 2
        assert message in capsys.readouterr().err
    assert out.read_text() == "the previous table\n"
