"""rawgment_ablation: the quick study runs end to end and the oracle beats the noisy input; the arms are
fed what they claim (noise variances on a flat scene); the same seeds give the same numbers; the
command refuses what it does not understand."""
import dataclasses
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
import torch

import rawgment as rg
import rawgment_ablation.study as ab


def tiny_config(**changes):
    """A study small enough to run in a second: it exercises every step, not the statistics."""
    config = ab.AblationConfig(conditions=[ab.Condition("x0.2", 0.2), ab.Condition("x0.5 blur3", 0.5, 1.0, 3.0, 0.0)],
                               seeds=2, iterations=3, batch=2, patch=16, trainScenes=2, trainSceneSize=32,
                               testScenes=1, testSceneSize=32, width=4, threads=1)
    return dataclasses.replace(config, **changes)


def test_quick_run_writes_the_report_and_the_oracle_beats_the_noisy_input(tmp_path):
    out = tmp_path / "quick"
    run = subprocess.run([sys.executable, "-m", "rawgment_ablation", "--quick", "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    # By default both kinds of network, each a full study in its own folder.
    for network, noiseMaps in (("told", True), ("blind", False)):
        for name in ("report.md", "results.json", "results.csv", "psnr.png"):
            assert (out / network / name).stat().st_size > 0, (network, name)
        assert (out / network / "psnr.png").read_bytes().startswith(b"\x89PNG")
        results = json.loads((out / network / "results.json").read_text())
        assert results["config"]["noiseMaps"] is noiseMaps
        assert [c["condition"]["name"] for c in results["conditions"]] == [c.name for c in ab.quickConditions()]
        for entry in results["conditions"]:
            arms = entry["arms"]
            assert set(arms) == set(ab.DEFAULT_ARMS)
            assert all(len(runs["psnr"]) == 2 and all(math.isfinite(v) for v in runs["psnr"])
                       for runs in arms.values())
            # The floor and the ceiling of the study: a network trained on exactly the test's kind of input
            # must improve on that input in every condition, or nothing else in the table means anything.
            assert np.mean(arms["ORACLE"]["psnr"]) > np.mean(arms["NOISY"]["psnr"]), entry["condition"]["name"]
        report = (out / network / "report.md").read_text()
        assert "![PSNR against darkening](psnr.png)" in report
        assert "ACCOUNT_PRIOR minus each arm" in report
        assert "x0.01 +12dB" in report
    both = (out / "report.md").read_text()
    assert "[told/report.md](told/report.md)" in both and "[blind/report.md](blind/report.md)" in both
    assert "| condition | prior share | told: minus IGNORE_PRIOR | blind: minus IGNORE_PRIOR | told: minus ORACLE |" \
        in both
    # One row per condition in each side-by-side table: ACCOUNT_PRIOR's tests and the control contrasts (here
    # only what IGNORE_PRIOR's and ACCOUNT_PRIOR's networks remove, the default run having no control arm).
    assert both.count("| x0.01 +12dB |") == 2
    assert "| condition | prior share | told: IGNORE_PRIOR minus ACCOUNT_PRIOR (removed/noise) |" in both
    assert "![PSNR against darkening, blind](blind/psnr.png)" in both


def test_per_condition_and_the_control_arms_from_the_command(tmp_path):
    # --per-condition trains per-condition networks beside the pooled ones, each study in its own folder; the
    # control arms run as any arm, and the page beside the studies states the predictions with outcomes.
    out = tmp_path / "mechanism"
    arms = "IGNORE_PRIOR,ACCOUNT_PRIOR,ORACLE,NOISY," + ",".join(ab.CONTROL_ARMS)
    assert ab.main(["--quick", "--per-condition", "--networks", "blind", "--arms", arms, "--seeds", "2",
                    "--iterations", "2", "--out", str(out)]) == 0
    for study, design in (("blind", "pooled"), ("blind-per-condition", "per-condition")):
        results = json.loads((out / study / "results.json").read_text())
        assert results["config"]["design"] == design and results["config"]["noiseMaps"] is False
        assert set(results["conditions"][0]["arms"]) == set(arms.split(","))
        assert all(len(v["removedNoiseRatio"]) == 2 for v in results["conditions"][0]["arms"].values())
        assert "The networks' implicit noise estimate" in (out / study / "report.md").read_text()
    page = (out / "report.md").read_text()
    assert "## The controls: predictions stated before the run, and outcomes" in page
    for prediction in ab.PREDICTIONS:
        assert "**%s** (blind networks, %s design)" % (prediction.name, prediction.design) in page
    # Two seeds cannot reach any corrected verdict: every prediction is undecided, none held by default.
    assert page.count("**Outcome: undecided (too few seeds") == len(ab.PREDICTIONS)
    assert "| condition | prior share | blind: IGNORE_PRIOR minus IGNORE_RESCALED | blind-per-condition:" in page
    run = subprocess.run([sys.executable, "-m", "rawgment_ablation", "--designs", "pooled,shuffled",
                          "--out", str(tmp_path / "x")], capture_output=True, text=True)
    assert run.returncode == 2 and "--designs must be pooled, per-condition or pooled,per-condition" in run.stderr


def test_the_plot_is_drawn_for_any_choice_of_arms():
    # Without the NOISY arm there is no gain over the noisy input to draw: that row of panels once became an
    # empty "plot" command, and gnuplot failed (a run with --arms IGNORE_PRIOR,ACCOUNT_PRIOR had no plot).
    # One condition per panel (a single photon ratio each) must draw too.
    config = tiny_config(conditions=[ab.Condition("x0.2", 0.2), ab.Condition("x0.2 +6dB", 0.2, 2.0),
                                     ab.Condition("x0.5 blur3", 0.5, 1.0, 3.0, 0.0)])
    rows = ab.summarize(ab.runAblation(dataclasses.replace(config, arms=("IGNORE_PRIOR", "ACCOUNT_PRIOR"))))
    for arms in (["IGNORE_PRIOR", "ACCOUNT_PRIOR"], ["ACCOUNT_PRIOR"]):
        script = ab._plotScript([r for r in rows if r["arm"] in arms], arms)
        assert all(line.strip() != "plot" for line in script.splitlines()), script
        assert "layout 1,3" in script
        png, why = ab._plotPng([r for r in rows if r["arm"] in arms], arms)
        assert why is None and png.startswith(b"\x89PNG"), why


def test_the_studies_report_sets_each_studys_differences_side_by_side_corrected_together(tmp_path):
    # The side-by-side table takes each cell from its own study's tests, Holm-corrected over all the page's
    # tests together: the same difference, interval and p as the study's own, a corrected p at least as large.
    byStudy = {"told": ab.runAblation(tiny_config()), "blind": ab.runAblation(tiny_config(noiseMaps=False)),
               "blind-per-condition": ab.runAblation(tiny_config(noiseMaps=False, design="per-condition"))}
    written, _ = ab.writeStudiesOutputs(byStudy, str(tmp_path / "all"))
    assert str(tmp_path / "all" / "report.md") in written
    report = (tmp_path / "all" / "report.md").read_text()
    family = ab.correctFamily([r for results in byStudy.values() for r in ab.contrastRows(results)])
    # 3 studies x 2 conditions x 3 tests: ACCOUNT_PRIOR minus IGNORE_PRIOR and ORACLE, and what IGNORE_PRIOR's
    # networks remove minus what ACCOUNT_PRIOR's do.
    assert len(family) == 3 * 2 * 3
    assert "over all 18 tests of this page together" in report
    header = next(l for l in report.splitlines() if l.startswith("| condition | prior share | told: minus"))
    columns = [c.strip() for c in header.strip("|").split(" | ")]
    for r in family:
        if r["metric"] != "psnr":
            continue
        study = "%s%s" % (r["network"], "" if r["design"] == "pooled" else "-per-condition")
        own = next(o for o in ab.contrastRows(byStudy[study]) if (o["condition"], o["b"]) == (r["condition"], r["b"]))
        assert (own["mean"], own["low"], own["high"], own["p"]) == (r["mean"], r["low"], r["high"], r["p"])
        assert r["pHolm"] >= own["pHolm"]
        line = next(l for l in report.splitlines() if l.startswith("| %s |" % r["condition"]))
        cell = line.strip("|").split(" | ")[columns.index("%s: minus %s" % (study, r["b"]))].strip()
        assert cell == "%+.2f [%+.2f, %+.2f], p %.2g, Holm %.2g (%s)" % (r["mean"], r["low"], r["high"], r["p"],
                                                                       r["pHolm"], r["verdictHolm"])
    for study in byStudy:
        assert (tmp_path / "all" / study / "results.json").exists()
        assert "[%s/report.md](%s/report.md)" % (study, study) in report


def test_studies_of_separate_runs_are_combined_into_one_corrected_page(tmp_path):
    # --combine reads the studies' results.json and writes the side-by-side page alone, Holm-corrected over
    # all their tests, linking to each study where it is; it refuses what would make a wrong page.
    studies = {"told": tiny_config(), "blind-per-condition": tiny_config(noiseMaps=False, design="per-condition")}
    for name, config in studies.items():
        ab.writeOutputs(ab.runAblation(config), str(tmp_path / "runs" / name / "study"))
    folders = [str(tmp_path / "runs" / name / "study") for name in studies]
    page = tmp_path / "page"
    assert ab.main(["--combine", *folders, "--out", str(page)]) == 0
    report = (page / "report.md").read_text()
    assert "over all 12 tests of this page together" in report  # 2 studies x 2 conditions x 3 tests
    assert "[../runs/told/study/report.md](../runs/told/study/report.md)" in report
    assert "| condition | prior share | told: minus IGNORE_PRIOR | blind-per-condition: minus IGNORE_PRIOR |" in report

    def refused(argv, message):
        run = subprocess.run([sys.executable, "-m", "rawgment_ablation", *argv], capture_output=True, text=True)
        assert run.returncode == 2 and message in run.stderr and "Traceback" not in run.stderr, run.stderr

    refused(["--combine", *folders, "--out", str(page)], "exists: outputs are never replaced")
    refused(["--combine", folders[0], folders[0], "--out", str(tmp_path / "p2")], "both trained replicate 0")
    refused(["--combine", str(tmp_path), "--out", str(tmp_path / "p3")], "results.json' cannot be read")
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "results.json").write_text("{\"config\": {}}")
    refused(["--combine", str(tmp_path / "bad"), "--out", str(tmp_path / "p4")], "is not the results.json of a")
    refused(["--combine", *folders, "--seeds", "3", "--out", str(tmp_path / "p5")],
            "--combine trains nothing, so --seeds would be ignored")
    other = str(tmp_path / "runs" / "other")
    ab.writeOutputs(ab.runAblation(tiny_config(conditions=tiny_config().conditions[:1])), other)
    refused(["--combine", folders[1], other, "--out", str(tmp_path / "p6")], "run on different conditions")
    assert not any((tmp_path / p).exists() for p in ("p2", "p3", "p4", "p5", "p6"))


def test_a_study_extended_with_later_replicates_merges_into_the_study_of_all_of_them(tmp_path):
    # Replicates 0-1 in one run, or replicate 1 then replicate 0 in two (--first-replicate): the same numbers,
    # merged in replicate order; runs that differ in more than their replicates are refused.
    whole = ab.runAblation(tiny_config(seeds=2))
    for first in (1, 0):
        ab.writeOutputs(ab.runAblation(tiny_config(seeds=1, firstReplicate=first)), str(tmp_path / ("r%d" % first)))
    from rawgment_ablation.report import loadStudy
    merged = ab.mergeReplicates([loadStudy(str(tmp_path / "r1")), loadStudy(str(tmp_path / "r0"))])
    assert [e["arms"] for e in merged["conditions"]] == [e["arms"] for e in whole["conditions"]]
    assert merged["config"]["seeds"] == 2 and merged["config"]["replicates"] == [[0, 0], [1, 1]]
    assert ab.main(["--combine", str(tmp_path / "r1"), str(tmp_path / "r0"), "--out", str(tmp_path / "page")]) == 0
    assert "2 seed(s) (replicates 0-0, 1-1, merged)" in (tmp_path / "page" / "report.md").read_text()
    ab.writeOutputs(ab.runAblation(tiny_config(seeds=1, firstReplicate=2, iterations=4)), str(tmp_path / "r2"))
    with pytest.raises(ValueError, match="differ in iterations: only their replicates may"):
        ab.writeCombinedReport([str(tmp_path / "r0"), str(tmp_path / "r2")], str(tmp_path / "page2"))


def test_runs_of_other_conditions_or_short_result_lists_are_never_merged(tmp_path):
    # The conditions are no part of a run's config: runs on x0.5, x0.2 and on x0.05, x0.01 (or the same
    # conditions reordered, or one condition against two) were merged into "4 seed(s)" over mixed PSNRs.
    def run(folder, conditions, first):
        ab.writeOutputs(ab.runAblation(tiny_config(seeds=1, firstReplicate=first, conditions=conditions)),
                        str(tmp_path / folder))
        return str(tmp_path / folder)

    bright = [ab.Condition("x0.5", 0.5), ab.Condition("x0.2", 0.2)]
    dark = [ab.Condition("x0.05", 0.05), ab.Condition("x0.01", 0.01)]
    base = run("bright0", bright, 0)
    for name, conditions in (("dark", dark), ("reordered", bright[::-1]), ("one", bright[:1])):
        other = run(name, conditions, 1)
        proc = subprocess.run([sys.executable, "-m", "rawgment_ablation", "--combine", base, other, "--out",
                               str(tmp_path / ("page-" + name))], capture_output=True, text=True)
        assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
        assert "differ in their conditions (x0.5, x0.2 against %s)" % ", ".join(
            c.name for c in conditions) in proc.stderr, proc.stderr
        assert not (tmp_path / ("page-" + name)).exists()
    # An arm whose list is shorter than the seeds was broadcast: one value paired with every seed.
    results = json.loads((tmp_path / "bright0" / "results.json").read_text())
    results["config"]["seeds"] = 4
    (tmp_path / "short").mkdir()
    (tmp_path / "short" / "results.json").write_text(json.dumps(results))
    proc = subprocess.run([sys.executable, "-m", "rawgment_ablation", "--combine", str(tmp_path / "short"),
                           "--out", str(tmp_path / "page-short")], capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert "short/results.json': condition x0.5, arm " in proc.stderr and "holds 1 psnr value(s) for its 4 seed(s)" \
        in proc.stderr, proc.stderr


def test_per_condition_networks_see_their_own_condition_alone():
    # A per-condition network of the first condition is the pooled network of a run with that condition
    # alone (the same crops, seeds and initial weights; its test captures are the first condition's in
    # both); the pooled networks of both conditions differ from it.
    conditions = tiny_config().conditions
    perCondition = ab.runAblation(tiny_config(design="per-condition"))
    alone = ab.runAblation(tiny_config(conditions=conditions[:1]))
    pooled = ab.runAblation(tiny_config())
    assert perCondition["config"]["design"] == "per-condition"
    assert perCondition["conditions"][0]["arms"] == alone["conditions"][0]["arms"]
    assert pooled["conditions"][0]["arms"]["ORACLE"]["psnr"] != alone["conditions"][0]["arms"]["ORACLE"]["psnr"]
    assert perCondition["conditions"][1]["arms"]["ORACLE"]["psnr"] != pooled["conditions"][1]["arms"]["ORACLE"]["psnr"]
    # The untrained floor does not depend on the design.
    assert perCondition["conditions"][1]["arms"]["NOISY"] == pooled["conditions"][1]["arms"]["NOISY"]
    with pytest.raises(ValueError, match="design must be one of pooled, per-condition"):
        tiny_config(design="mixed").validate()


def test_the_same_seeds_give_the_same_numbers_and_another_seed_does_not():
    first = ab.runAblation(tiny_config())
    again = ab.runAblation(tiny_config())
    other = ab.runAblation(tiny_config(seed=1))
    scores = [[entry["arms"] for entry in r["conditions"]] for r in (first, again, other)]
    assert scores[0] == scores[1]
    assert scores[0] != scores[2]


# rawgment.deriveSeed(1, SEED_ABLATION, 3) while the package still named the purpose (the build of cb7e969).
RECORDED_STUDY_SEED_1_3 = 1057235584146246385


def test_the_studys_seeds_are_the_librarys_derivation_under_its_reserved_purpose():
    # The study's seeds are rawgment.deriveSeed under purpose 24, which the package no longer names (a study
    # is not part of it): the Python mixing gives the library's own derived seeds for every purpose it has, so
    # under 24 it gives what deriveSeed(seed, 24, index) gave when the package named it (recorded below).
    from rawgment_ablation.common import STUDY_SEED_PURPOSE, derive_seed, study_seed
    for purpose in rg.SeedPurpose.__members__.values():
        for seed, index in ((0, 0), (7, 3), (2**64 - 1, 2**40 + 5)):
            assert derive_seed(seed, int(purpose), index) == rg.deriveSeed(seed, purpose, index)
    assert STUDY_SEED_PURPOSE not in [int(p) for p in rg.SeedPurpose.__members__.values()]
    with pytest.raises(Exception, match="unknown purpose 24"):
        rg.deriveSeed(1, rg.SeedPurpose(24), 0)
    assert study_seed(1, 3) == RECORDED_STUDY_SEED_1_3


def test_a_blind_study_feeds_its_networks_the_image_only(tmp_path):
    # --blind: the networks take the four planes without noise maps (the paper's detectors see only the
    # image), start as the identity like the told networks, and the run and its report say so.
    blind = ab.Denoiser(width=4, noiseMaps=False)
    x = torch.rand(2, 4, 8, 8)
    assert torch.equal(blind(x), x)
    with pytest.raises(RuntimeError):
        blind(torch.rand(2, 8, 8, 8))  # a noise map is not an input it takes
    results = ab.runAblation(tiny_config(noiseMaps=False))
    assert results["config"]["noiseMaps"] is False
    for entry in results["conditions"]:
        for runs in entry["arms"].values():
            assert all(math.isfinite(v) for v in runs["psnr"])
    written, _ = ab.writeOutputs(results, str(tmp_path / "blind"))
    assert "blind: they see the image only (--blind)" in (tmp_path / "blind" / "report.md").read_text()
    told = ab.runAblation(tiny_config())
    assert [e["arms"]["ORACLE"]["psnr"] for e in told["conditions"]] != \
        [e["arms"]["ORACLE"]["psnr"] for e in results["conditions"]]
    # The blind residual unit is the run's, and it changes what the blind networks learn.
    assert ab.Denoiser(width=4, noiseMaps=False, blindScale=0.05).blindScale == 0.05
    assert results["config"]["blindStep"] == ab.BLIND_STEP
    coarser = ab.runAblation(tiny_config(noiseMaps=False, blindStep=0.05))
    assert coarser["config"]["blindStep"] == 0.05
    assert [e["arms"]["ORACLE"]["psnr"] for e in coarser["conditions"]] != \
        [e["arms"]["ORACLE"]["psnr"] for e in results["conditions"]]


def test_the_arms_are_fed_the_noise_they_claim():
    """On a flat mid-grey scene, the training inputs' noise variance (green planes, network scale) is the
    target's for ORACLE and ACCOUNT_PRIOR, (1 + prior share) times it for IGNORE_PRIOR and the share alone
    for NONE: the four arms differ in exactly what the study says they differ in. The control arms too:
    IGNORE_PRIOR rescaled and ACCOUNT_PRIOR with Poisson draws carry the target's variance, the oracle with
    the prior share added (1 + share) times it."""
    config = ab.AblationConfig(conditions=[ab.Condition("x0.5", 0.5)], patch=256)
    study = ab._Study(config)
    condition = config.conditions[0]
    flat = np.full((256, 256, 3), ab._MID_GREY, np.float32)
    mean = ab.mosaicOfScene(flat, study.params.pattern, study.level)
    inputs = study.trainingInputs(mean, condition, ab.TRAINED_ARMS, seed=11)
    target = study.targetVariance(condition)
    share = study.priorShare(condition)
    expected = {"ORACLE": target, "ACCOUNT_PRIOR": target, "IGNORE_PRIOR": (1 + share) * target,
                "NONE": share * target, "IGNORE_RESCALED": target, "ORACLE_PLUS_SHARE": (1 + share) * target,
                "ACCOUNT_POISSON": target, "DARK_BANK": target,
                # Whole frames drawn from 25 lack 1/25 of the read part, under 0.4% of the target here.
                "DARK_BANK_IGNORE": (1 + share) * target}
    assert set(expected) == set(ab.TRAINED_ARMS)
    # 2 x 128 x 128 green samples: a sample variance's relative standard deviation is sqrt(2 / n) = 0.55%;
    # 4% is above 7 of them, and far below the 49% that separates ACCOUNT_PRIOR from IGNORE_PRIOR here.
    assert 0.4 < share < 0.6
    for arm, planes in inputs.items():
        green = planes[1:3].double()
        variance = float(((green - green.mean(dim=(1, 2), keepdim=True)) ** 2).sum() / (green.numel() - 2))
        assert variance == pytest.approx(expected[arm], rel=0.04), arm
        # The noise map the network is given is the model's prediction for the target, for every arm.
        assert float(planes[5:7].double().pow(2).mean()) == pytest.approx(target, rel=0.04), arm
    # Each control changes one thing of the arm it is made from and keeps its draws: IGNORE_RESCALED is
    # IGNORE_PRIOR's noise scaled (on a flat plane by one factor, so perfectly correlated with it, up to
    # float32 rounding), and ORACLE_PLUS_SHARE is the oracle's capture plus independent noise of the share's
    # variance.
    # Both are rounded to whole DN as captures are, which leaves the rescaled noise correlated with its source
    # above 0.995 (rounding adds 1/12 DN^2 to a variance of about 300 DN^2 at x0.5 mid-grey).
    for plane in range(4):
        ignore, rescaled = inputs["IGNORE_PRIOR"][plane].flatten(), inputs["IGNORE_RESCALED"][plane].flatten()
        assert float(torch.corrcoef(torch.stack([ignore, rescaled]).double())[0, 1]) > 0.995, plane
    bright = study.brightCapture(mean, 11)
    ignoreRaw = study.augmented(bright, condition, "IGNORE_PRIOR", 11)
    assert study.rescaledToTarget(ignoreRaw, mean, condition).dtype == ignoreRaw.dtype == np.uint16
    assert study.withPriorShare(ignoreRaw, mean, condition, 11).dtype == np.uint16
    raws = {arm: study.trainingInputs(mean, condition, [arm], seed=11)[arm] for arm in ab.CONTROL_ARMS}
    assert all(torch.equal(raws[arm], inputs[arm]) for arm in ab.CONTROL_ARMS)  # the same draws, alone or not
    extra = (inputs["ORACLE_PLUS_SHARE"][1:3] - inputs["ORACLE"][1:3]).double()
    assert float(extra.var()) == pytest.approx(share * target, rel=0.04)
    # Independent: over 2 x 128 x 128 samples a correlation's standard error is 1 / sqrt(32768) = 0.0055.
    pair = torch.stack([extra.flatten(), inputs["ORACLE"][1:3].flatten().double()])
    assert abs(float(torch.corrcoef(pair)[0, 1])) < 0.02


def test_the_bank_arms_carry_what_the_departing_sensor_has_and_the_components_lack(tmp_path):
    """On a black scene at x0.5 (k = 0.5) of the departing sensor (hot pixels left out), the training inputs'
    pixel variance and column-mean variance (DN^2; the departures: column banding 2, DSNU 2 DN, 1% of pixels
    with 100 more): DARK_BANK carries the oracle's; ACCOUNT_PRIOR, whose components have none of them, keeps only
    k^2 of the input's (its pixel variance 16% low, its columns 0.5 + v/256 against 2 + v/256); the peer's
    whole frames add k^2 of the input's whole read variance on top (25%)."""
    config = ab.AblationConfig(conditions=[ab.Condition("x0.5", 0.5)], patch=256, departingSensor=True)
    study = ab._Study(config)
    condition = config.conditions[0]
    mean = np.zeros((256, 256), np.float32)
    arms = ("ORACLE", "ACCOUNT_PRIOR", "DARK_BANK", "DARK_BANK_IGNORE")
    inputs = study.trainingInputs(mean, condition, arms, seed=5)
    scale = float(study.range * condition.photonRatio * condition.gainRatio)
    figures = {}
    for arm in arms:
        planes = inputs[arm][:4].double() * scale  # DN at the target
        ordinary = planes < 0.5 * scale  # hot pixels sit near white
        values = planes[ordinary]
        pixel = float(values.var())
        # Mosaic columns: each plane's columns are means over its 128 rows (hot pixels out).
        counts = ordinary.sum(dim=1).double()
        columnMeans = (planes * ordinary).sum(dim=1) / counts
        figures[arm] = (pixel, float(columnMeans.var()))
    oracle = figures["ORACLE"]
    # 4 x 128 x 128 pixels: a variance's relative error is about 1% (heavy tails and noisy pixels included);
    # 512 column means: sqrt(2 / 511) = 6%.
    assert figures["DARK_BANK"][0] == pytest.approx(oracle[0], rel=0.05)
    assert figures["DARK_BANK"][1] == pytest.approx(oracle[1], rel=0.25)
    assert figures["ACCOUNT_PRIOR"][0] < 0.9 * oracle[0]
    assert figures["ACCOUNT_PRIOR"][1] < 0.6 * oracle[1]
    assert figures["DARK_BANK_IGNORE"][0] > 1.15 * oracle[0]


def test_the_bank_arms_run_and_their_contrasts_reach_the_report(tmp_path):
    out = tmp_path / "bank"
    assert ab.main(["--quick", "--networks", "told", "--departing-sensor", "--arms",
                    "ACCOUNT_PRIOR,ORACLE,DARK_BANK,DARK_BANK_IGNORE", "--seeds", "2", "--iterations", "2",
                    "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    assert results["config"]["departingSensor"] is True and results["config"]["bankFrames"] == 25
    assert set(results["conditions"][0]["arms"]) == {"ACCOUNT_PRIOR", "ORACLE", "DARK_BANK", "DARK_BANK_IGNORE"}
    report = (out / "report.md").read_text()
    assert "The simulated sensor departs from the model (--departing-sensor)" in report
    for a, b, _ in ab.BANK_CONTRASTS:
        assert "| %s minus %s | PSNR dB |" % (a, b) in report, (a, b)


def test_ssim_and_psnr_on_known_cases():
    generator = torch.Generator().manual_seed(3)
    clean = torch.rand(4, 40, 40, generator=generator, dtype=torch.float64)
    assert ab.ssim(clean, clean) == pytest.approx(1.0, abs=1e-12)
    assert ab.psnr(clean, clean) == math.inf
    # A constant error of 0.1 on a peak of 1: MSE 0.01, 20 dB (float64, so exact to rounding).
    assert ab.psnr(clean + 0.1, clean) == pytest.approx(20.0, abs=1e-9)
    noisy = clean + 0.05 * torch.randn(4, 40, 40, generator=generator, dtype=torch.float64)
    assert ab.ssim(noisy, clean) < 0.99
    assert ab.ssim(noisy, clean) > ab.ssim(clean + 0.2 * torch.randn(4, 40, 40, generator=generator, dtype=torch.float64), clean)
    # Against SSIM written out from its definition: the 11x11 window applied at every valid position.
    assert ab.ssim(noisy, clean) == pytest.approx(ssim_from_the_definition(noisy.numpy(), clean.numpy()), abs=1e-12)


def ssim_from_the_definition(x, y):
    taps = np.arange(11) - 5.0
    g = np.exp(-taps ** 2 / 4.5)
    window = np.outer(g, g) / g.sum() ** 2
    views = [np.lib.stride_tricks.sliding_window_view(v, (11, 11), axis=(1, 2)) for v in (x, y)]

    def mean(a):
        return np.einsum("chwij,ij->chw", a, window)

    mx, my = mean(views[0]), mean(views[1])
    vx, vy = mean(views[0] ** 2) - mx ** 2, mean(views[1] ** 2) - my ** 2
    cxy = mean(views[0] * views[1]) - mx * my
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    return float(np.mean((2 * mx * my + c1) * (2 * cxy + c2) / ((mx ** 2 + my ** 2 + c1) * (vx + vy + c2))))


def test_the_verdict_needs_the_interval_and_the_sign_flip_test():
    results = {"conditions": [{"condition": dataclasses.asdict(ab.Condition("c", 0.2)), "priorShare": 0.2, "arms": {
        "ACCOUNT_PRIOR": {"psnr": [30.0, 30.2, 30.4], "ssim": [0.9] * 3},
        "IGNORE_PRIOR": {"psnr": [29.9, 30.3, 30.3], "ssim": [0.9] * 3},
        "NONE": {"psnr": [28.0, 28.1, 28.3], "ssim": [0.8] * 3},
        "ORACLE": {"psnr": [31.0, 31.2, 31.4], "ssim": [0.95] * 3}}}]}
    rows = {row["arm"]: row for row in ab.summarize(results)}
    # Three seeds of one sign put the interval off 0, but p cannot fall below 0.25: a lean, no verdict.
    assert {arm: row.get("verdict") for arm, row in rows.items()} == {
        "ACCOUNT_PRIOR": None, "IGNORE_PRIOR": "tie", "NONE": "ACCOUNT_PRIOR leans better",
        "ORACLE": "ACCOUNT_PRIOR leans worse"}
    # ACCOUNT_PRIOR minus IGNORE_PRIOR is +0.1, -0.1, +0.1 by seed: the interval holds 0, and every sign
    # pattern's mean (+-0.033 or +-0.1) is at least the observed 0.033 in size (p = 1).
    assert rows["IGNORE_PRIOR"]["accountMinusLow"] < 0 < rows["IGNORE_PRIOR"]["accountMinusHigh"]
    assert rows["IGNORE_PRIOR"]["pValue"] == pytest.approx(1.0)
    # NONE is worse by 2.0, 2.1, 2.1: the interval is the range of the resampled means.
    assert rows["NONE"]["accountMinusLow"] == pytest.approx(2.0, abs=1e-9)
    assert rows["NONE"]["accountMinusHigh"] == pytest.approx(2.1, abs=1e-9)
    assert rows["NONE"]["pValue"] == pytest.approx(0.25)  # 2 / 2^3, the smallest 3 seeds allow
    # Six seeds of one sign: p = 2 / 2^6 = 0.031 <= 0.05, a verdict. Five of -1 and one of +0.3 leave
    # the interval off 0, but the sign patterns whose mean is as large are 4 of 64 (these two and their
    # mirror images: flipping a -1 shrinks the mean), p = 0.0625: a lean.
    six = {"conditions": [{"condition": dataclasses.asdict(ab.Condition("c", 0.2)), "priorShare": 0.2, "arms": {
        "ACCOUNT_PRIOR": {"psnr": [30.0, 30.2, 30.4, 30.1, 30.3, 30.2], "ssim": [0.9] * 6},
        "NONE": {"psnr": [29.0, 29.1, 29.3, 29.0, 29.2, 29.1], "ssim": [0.8] * 6},
        "ORACLE": {"psnr": [31.0, 31.2, 31.4, 31.1, 31.3, 29.9], "ssim": [0.95] * 6}}}]}
    rows = {row["arm"]: row for row in ab.summarize(six)}
    assert rows["NONE"]["pValue"] == pytest.approx(2 / 64) and rows["NONE"]["verdict"] == "ACCOUNT_PRIOR better"
    # Corrected over the report's 2 tests (ACCOUNT_PRIOR minus NONE and minus ORACLE), the smaller p doubles
    # (Holm's first step) to 0.0625: no longer a verdict, a lean; 7 seeds would be needed for any verdict.
    assert rows["NONE"]["pHolm"] == pytest.approx(4 / 64) and rows["NONE"]["verdictHolm"] == "ACCOUNT_PRIOR leans better"
    assert ab.seedsForFamily(2) == 7
    assert rows["ORACLE"]["accountMinusHigh"] < 0 and rows["ORACLE"]["pValue"] == pytest.approx(4 / 64)
    assert rows["ORACLE"]["verdict"] == "ACCOUNT_PRIOR leans worse"


#: R 4.2.2's p.adjust(c(0.01, 0.04, 0.03, 0.005, 0.2, 0.03), "holm").
HOLM_REFERENCE = [0.05, 0.12, 0.12, 0.03, 0.2, 0.12]


def test_holms_correction_against_r():
    # Reference: R 4.2's p.adjust(p, "holm") (Rscript -e 'print(p.adjust(c(0.01, 0.04, 0.03, 0.005, 0.2, 0.03),
    # "holm"), digits=17)'), values exact to the float rounding of (m - i + 1) p; ties keep their order.
    p = [0.01, 0.04, 0.03, 0.005, 0.2, 0.03]
    assert ab.holmAdjusted(p) == pytest.approx(HOLM_REFERENCE, rel=1e-12)
    assert ab.holmAdjusted([]) == [] and ab.holmAdjusted([0.7]) == [0.7]
    # The fewest seeds whose exact sign-flip test reaches 0.05 / m: 2 / 2^n <= 0.05 / m.
    assert [ab.seedsForFamily(m) for m in (1, 2, 12, 36, 51, 52)] == [6, 7, 9, 11, 11, 12]
    # The default run's 2 studies of 9 conditions make 3 tests each (ACCOUNT_PRIOR minus IGNORE_PRIOR and
    # ORACLE, and the removed/noise contrast): 54 tests, 12 seeds. Without a test, the old default of 6.
    assert ab.seedsNeeded(ab.AblationConfig(), 2) == 12
    assert ab.seedsNeeded(ab.AblationConfig(arms=("ORACLE", "NOISY"))) == 6
    assert ab.runAblation(tiny_config(seeds=0, arms=("ORACLE", "NOISY")))["config"]["seeds"] == 6
    # The planning figure: never fewer than the family's floor, more for a noisy difference, none for 0.
    assert ab.seedsToConfirm(1.0, 0.0, 12) == 9 and ab.seedsToConfirm(0.0, 1.0, 12) is None
    # (z sd / mean)^2 with z the normal quantile at 1 - 0.05 / (2 x 12): R's qnorm(1 - 0.05/24) = 2.865260239,
    # so (2.865260239 x 2)^2 = 32.84, 33 seeds.
    assert ab.seedsToConfirm(0.2, 0.4, 12) == 33


def test_a_prediction_holds_only_when_every_condition_in_its_scope_agrees():
    prediction = next(p for p in ab.PREDICTIONS if p.name == "excess variance (rescaled)")
    assert (prediction.a, prediction.b, prediction.network, prediction.design, prediction.expect) == \
        ("IGNORE_PRIOR", "IGNORE_RESCALED", "blind", "pooled", "a")

    def row(condition, share, direction):
        return {"condition": condition, "priorShare": share, "a": "IGNORE_PRIOR", "b": "IGNORE_RESCALED",
                "metric": "psnr", "network": "blind", "design": "pooled", "directionHolm": direction, "n": 12,
                "seedsForFamily": 11}

    from rawgment_ablation.controls import predictionOutcome
    # The small-share condition is out of its scope, whatever it shows.
    rows = [row("x0.5", 0.48, "a"), row("x0.2", 0.17, "a"), row("x0.01", 0.002, "b")]
    assert predictionOutcome(prediction, rows)[0] == "held"
    assert predictionOutcome(prediction, [row("x0.5", 0.48, "a"), row("x0.2", 0.17, None)])[0] == "undecided"
    assert predictionOutcome(prediction, [row("x0.5", 0.48, "a"), row("x0.2", 0.17, "b")])[0] == "contradicted"
    assert predictionOutcome(prediction, [row("x0.01", 0.002, "a")]) is None
    tie = next(p for p in ab.PREDICTIONS if p.expect == "tie" and p.design == "pooled")
    ties = [dict(row("x0.5", 0.48, None), a=tie.a, b=tie.b), dict(row("x0.2", 0.17, None), a=tie.a, b=tie.b)]
    assert predictionOutcome(tie, ties)[0] == "held"
    ties[1]["directionHolm"] = "b"
    assert predictionOutcome(tie, ties)[0] == "contradicted"
    # Below the seeds any corrected verdict needs, a tie is no evidence and nothing is decided.
    ties[1].update(directionHolm=None, n=6)
    assert predictionOutcome(tie, ties)[0].startswith("undecided (too few seeds")


def test_paired_significance_against_known_cases():
    # Six seeds all +1: the interval is [1, 1] and only the all-positive and all-negative patterns reach
    # the observed mean (p = 2/64). Differences centred on 0 give p = 1 and an interval around 0.
    low, high, p = ab.pairedSignificance([1.0] * 6, seed=1)
    assert (low, high) == (1.0, 1.0) and p == pytest.approx(2 / 64)
    low, high, p = ab.pairedSignificance([0.5, -0.5, 0.3, -0.3], seed=1)
    assert low < 0 < high and p == pytest.approx(1.0)
    # Above 16 replicates the p of a random 65536 sign patterns counts the data's own: never 0, and for 24
    # agreeing replicates (an exact p of 2 / 2^24) at most 1 / 65537 plus the chance of drawing either
    # all-equal pattern.
    p = ab.pairedSignificance([0.3] * 24, seed=1)[2]
    assert 0 < p <= 2 / 65537
    # The same seed, the same interval.
    assert ab.pairedSignificance([0.2, 0.5, -0.1, 0.4, 0.3], seed=9) == ab.pairedSignificance(
        [0.2, 0.5, -0.1, 0.4, 0.3], seed=9)


def test_a_calibrated_model_is_the_one_simulated(tmp_path):
    model = rg.NoiseModel(alpha=0.4, sigmaD2=2.0, sigmaR2=3.0)
    model.save(str(tmp_path / "model.yml"))
    out = tmp_path / "out"
    assert ab.main(["--model", str(tmp_path / "model.yml"), "--quick", "--seeds", "1", "--iterations", "1",
                    "--arms", "ORACLE,NOISY", "--networks", "told", "--out", str(out)]) == 0
    written = json.loads((out / "results.json").read_text())["config"]["model"]
    # The simulator re-adds the rounding's 1/12 DN^2 that the study takes out: the effective model is
    # the file's, up to the float rounding of the file.
    assert written == pytest.approx({"alpha": 0.4, "sigmaD2": 2.0, "sigmaR2": 3.0}, rel=1e-6)


def test_a_model_with_every_dark_frame_component_reaches_the_captures_and_the_report(tmp_path):
    # Row noise, heavy-tailed read noise and dark shading of the model: the study's simulators draw them
    # (their effective model has them, the maps cropped to each capture), the augmentation adds them, and
    # results.json and the report say so.
    model = rg.NoiseModel(alpha=0.4, sigmaD2=2.0, sigmaR2=3.0)
    model.rowSigmaD2, model.rowSigmaR2 = 0.2, 0.5
    model.tukeyRead, model.tukeyLambda = True, -0.05
    rng = np.random.default_rng(3)
    model.darkShadingPerGain = rng.normal(0, 0.5, (64, 64)).astype(np.float32)
    model.darkShadingOffset = rng.normal(0, 1.0, (64, 64)).astype(np.float32)
    config = tiny_config(model=model)
    for size in (16, 32):
        effective = rg.SensorSimulator(config.sensorParams(size), (size, size)).effectiveModel()
        assert effective.rowSigmaD2 == pytest.approx(0.2) and effective.tukeyRead
        np.testing.assert_array_equal(effective.darkShadingPerGain, model.darkShadingPerGain[:size, :size])
    results = ab.runAblation(config)
    written = results["config"]["model"]
    assert written["rowSigmaD2"] == pytest.approx(0.2) and written["tukeyLambda"] == pytest.approx(-0.05)
    assert written["darkShading"] == [64, 64]
    ab.writeOutputs(results, str(tmp_path / "dark"))
    report = (tmp_path / "dark" / "report.md").read_text()
    assert "Dark-frame components in every capture and augmentation: row noise" in report
    assert "dark shading (maps 64x64)" in report
    # Maps smaller than the study's captures are refused, naming both sizes.
    small = rg.NoiseModel(alpha=0.4, sigmaD2=2.0, sigmaR2=3.0)
    small.darkShadingPerGain = np.zeros((16, 16), np.float32)
    small.darkShadingOffset = np.zeros((16, 16), np.float32)
    with pytest.raises(ValueError, match="16x16, smaller than the study's 32x32"):
        tiny_config(model=small).validate()


def test_a_real_camera_from_darktables_profiles_is_the_one_simulated(tmp_path):
    fmt = rg.RawFormat(blackLevel=(256, 256, 256, 256), whiteLevel=4095)
    truth = rg.NoiseModel(alpha=0.3, sigmaD2=1.0, sigmaR2=4.0)
    (tmp_path / "noiseprofiles.json").write_text(
        rg.darktableNoiseProfiles(truth, fmt, 100, [100, 400, 1600], "Maker", "Cam"))
    out = tmp_path / "out"
    assert ab.main(["--model", str(tmp_path / "noiseprofiles.json"), "--camera", "Maker Cam", "--quick", "--seeds",
                    "1", "--iterations", "1", "--arms", "ORACLE,NOISY", "--networks", "told",
                    "--out", str(out)]) == 0
    config = json.loads((out / "results.json").read_text())["config"]
    assert config["camera"] == "Maker Cam"
    assert config["model"] == pytest.approx({"alpha": 0.3, "sigmaD2": 1.0, "sigmaR2": 4.0}, rel=1e-6)
    assert "The noise of the real camera 'Maker Cam'" in (out / "report.md").read_text()
    assert ab.main(["--model", str(tmp_path / "noiseprofiles.json"), "--out", str(tmp_path / "x")]) == 2
    assert ab.main(["--camera", "Maker Cam", "--out", str(tmp_path / "y")]) == 2


@pytest.mark.parametrize("argv, message", [
    (["--bogus"], "unrecognized arguments: --bogus"),
    (["--arms", "ACCOUNT_PRIOR,SOMETIMES"], "SOMETIMES"),
    (["--model", "/nonexistent/model.yml"], "/nonexistent/model.yml"),
    (["--seeds", "0"], "seeds must be >= 1"),
    (["--conditions", "x0.2,x0.3"], "unknown condition(s) x0.3"),
    (["--networks", "told,deaf"], "--networks must be told, blind or told,blind, got 'told,deaf'"),
    (["--blind-step", "0"], "blindStep in (0, 1]"),
    (["--shot-sampling", "binomial"], "shotSampling must be GAUSSIAN or POISSON"),
    # Once tracebacks: each option's range is checked before anything runs.
    (["--seed=-1"], "--seed must be in [0, 2^64), got -1"),
    (["--seed=%d" % 2 ** 64], "--seed must be in [0, 2^64)"),
    (["--threads=-1"], "--threads must be >= 0"),
    (["--base-gain-db=nan"], "--base-gain-db must be finite, got nan"),
])
def test_the_command_refuses_what_it_does_not_understand(argv, message, tmp_path, capsys):
    # In this process: a program of its own per case spent 1.3 s importing torch, for what main() decides
    # alone. test_help_names_the_options runs the module as users do.
    assert main_exit_code(["--out", str(tmp_path / "x"), *argv]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def main_exit_code(argv):
    """What `python3 -m rawgment_ablation ARGV` would exit with: argparse's own refusals exit."""
    try:
        return ab.main(argv)
    except SystemExit as e:
        return e.code


def test_an_out_that_cannot_take_the_outputs_is_refused_before_any_training(tmp_path, capsys):
    # A previous run's folder or a file at --out once failed after all the training, with a traceback.
    quick = ["--quick", "--seeds", "1", "--iterations", "1", "--arms", "ORACLE,NOISY", "--networks", "told"]
    afile = tmp_path / "afile"
    afile.write_text("mine")
    previous = tmp_path / "previous"
    previous.mkdir()
    (previous / "report.md").write_text("an earlier report")
    both = tmp_path / "both"
    (both / "blind").mkdir(parents=True)
    (both / "blind" / "results.json").write_text("{}")
    for out, extra, message in ((afile, [], "exists and is not a folder"),
                                (previous, [], "holds a previous run's '%s'" % (previous / "report.md")),
                                (both, ["--networks", "told,blind"], str(both / "blind" / "results.json")),
                                (tmp_path / "afile" / "sub", [], "is not a writable folder")):
        assert main_exit_code([*quick, *extra, "--out", str(out)]) == 2
        captured = capsys.readouterr()
        assert message in captured.err
        assert "iteration" not in captured.out and "training" not in (captured.out + captured.err).lower()
    assert afile.read_text() == "mine"
    assert (previous / "report.md").read_text() == "an earlier report"


def test_help_names_the_options():
    run = subprocess.run([sys.executable, "-m", "rawgment_ablation", "--help"], capture_output=True, text=True)
    assert run.returncode == 0
    for option in ("--model", "--quick", "--out", "--seeds", "--arms"):
        assert option in run.stdout


def test_the_dark_components_model_of_the_results_page_serves_the_default_study(tmp_path):
    # studies/ablation/dark_components_model.py writes the model of docs/results.md's run with every
    # dark-frame component: the file it writes must load with all of them, and its maps must cover the
    # default study's largest capture (or that run would be refused).
    path = tmp_path / "dark.yml"
    tool = os.path.join(os.path.dirname(__file__), "..", "dark_components_model.py")
    run = subprocess.run([sys.executable, tool, str(path)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    model = rg.NoiseModel.load(str(path))
    assert model.rowSigmaD2 > 0 and model.rowSigmaR2 > 0 and model.tukeyRead and model.hasDarkShading()
    config = ab.AblationConfig(model=model)
    assert model.darkShadingPerGain.shape[0] >= config.testSceneSize
    config.validate()


def test_the_default_thread_count_honours_omp_num_threads(monkeypatch):
    # The test suite sets OMP_NUM_THREADS=1 so that a study beside other tests does not fight them for
    # the cores; without it (or with nonsense) a study takes every core.
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    assert ab._defaultThreads() == 1
    assert ab.runAblation(tiny_config(threads=0, seeds=1, arms=("NOISY",)))["config"]["threads"] == 1
    monkeypatch.setenv("OMP_NUM_THREADS", "many")
    assert ab._defaultThreads() == (os.cpu_count() or 1)
    monkeypatch.delenv("OMP_NUM_THREADS")
    assert ab._defaultThreads() == (os.cpu_count() or 1)


def test_the_augmentation_options_reach_the_augmented_arms_only(tmp_path):
    # POISSON shot draws and the local mean change what the augmented arms are fed (so what they learn),
    # not the oracle, whose captures the simulator makes; the run and its report say which were used.
    plain = ab.runAblation(tiny_config(arms=("ACCOUNT_PRIOR", "ORACLE")))
    other = ab.runAblation(tiny_config(arms=("ACCOUNT_PRIOR", "ORACLE"), shotSampling="POISSON",
                                       priorMean="LOCAL_MEAN"))
    assert other["config"]["shotSampling"] == "POISSON" and other["config"]["priorMean"] == "LOCAL_MEAN"
    arm = lambda r, name: [e["arms"][name]["psnr"] for e in r["conditions"]]
    assert arm(plain, "ORACLE") == arm(other, "ORACLE")
    assert arm(plain, "ACCOUNT_PRIOR") != arm(other, "ACCOUNT_PRIOR")
    ab.writeOutputs(other, str(tmp_path / "options"))
    assert "ShotNoiseSampling::POISSON" in (tmp_path / "options" / "report.md").read_text()
