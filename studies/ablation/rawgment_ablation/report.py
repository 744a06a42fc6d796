"""The report of the ablation study (rawgment_ablation): paired significance (bootstrap interval, sign-flip test) with Holm's
correction over a report's tests, the summary rows, the PSNR plot, report.md, results.json and results.csv,
for one study or several side by side. Use it through rawgment_ablation.study."""
import json
import math
import os
import subprocess
from statistics import NormalDist

import numpy as np

import rawgment as _rg
from rawgment_ablation.common import ARMS, BLIND_STEP, TRAINED_ARMS, _ROLE_BOOTSTRAP, _seed
from rawgment_ablation.controls import BANK_CONTRASTS, CONTROL_CONTRASTS, PREDICTIONS, predictionOutcome

__all__ = ["pairedSignificance", "summarize", "writeOutputs", "writeStudiesOutputs", "writeCombinedReport", "mergeReplicates", "loadStudy",
           "studyName", "holmAdjusted", "seedsForFamily", "seedsToConfirm", "contrastRows", "correctFamily", "NETWORKS",
           "SIGNIFICANCE"]


def _meanSd(values):
    v = np.asarray(values, dtype=np.float64)
    return float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else 0.0


#: Resamples of the paired bootstrap interval of ACCOUNT_PRIOR minus an arm.
_BOOTSTRAP_RESAMPLES = 20000


def pairedSignificance(differences, seed):
    """The significance of paired differences (one per training replicate): the 95% percentile bootstrap
    interval of their mean (resampling replicates, from `seed`) and the exact two-sided sign-flip
    permutation p-value (every one of the 2^n sign patterns; above 16 replicates a random 65536 of them,
    p = (k + 1) / 65537 with k of them as extreme as the data: the data's own pattern counts, so a Monte
    Carlo p is never 0). With n replicates the smallest p is 2 / 2^n: 0.25 at 3, 0.0625 at 5, 0.031 at 6."""
    d = np.asarray(differences, dtype=np.float64)
    n = d.size
    rng = np.random.default_rng(seed)
    means = d[rng.integers(0, n, size=(_BOOTSTRAP_RESAMPLES, n))].mean(axis=1)
    low, high = np.percentile(means, [2.5, 97.5])
    if n <= 16:
        signs = 1 - 2 * ((np.arange(2 ** n)[:, None] >> np.arange(n)) & 1)
        return float(low), float(high), float(np.mean(np.abs((signs * d).mean(axis=1)) >= abs(d.mean()) - 1e-12))
    signs = rng.choice([-1, 1], size=(65536, n))
    extreme = int(np.sum(np.abs((signs * d).mean(axis=1)) >= abs(d.mean()) - 1e-12))
    return float(low), float(high), (extreme + 1) / (signs.shape[0] + 1)


#: The family-wise error rate of a report's tests: each report corrects its p-values by Holm's method over
#: every paired test it makes, and calls a difference a verdict only when its corrected p is at most this.
SIGNIFICANCE = 0.05


def _verdict(low, high, pValue, subject="ACCOUNT_PRIOR", words=("better", "worse")):
    """'tie' when the 95% bootstrap interval holds 0; when it does not, '<subject> better' (or 'worse') if
    the sign-flip p is at most SIGNIFICANCE too, else '<subject> leans better' (or 'leans worse'). A
    percentile bootstrap over a handful of replicates is too narrow (3 replicates of one sign always give
    an interval off 0), so the interval alone never makes a verdict: with fewer than 6 replicates p cannot
    reach 0.05 and the most a difference can do is lean. Given a Holm-corrected p, the verdict is the
    family's."""
    if low <= 0 <= high:
        return "tie"
    direction = words[0] if low > 0 else words[1]
    return subject + " " + (direction if pValue <= SIGNIFICANCE else "leans " + direction)


def holmAdjusted(pValues):
    """Holm's step-down adjusted p-values, in the given order: the i-th smallest p times (m - i + 1),
    never below an earlier one's, at most 1. A test is significant at family-wise level alpha when its
    adjusted p is at most alpha; it controls the family-wise error under any dependence between the tests
    (the conditions of one pooled network are far from independent)."""
    p = np.asarray(pValues, dtype=np.float64)
    m = p.size
    adjusted = np.empty(m)
    running = 0.0
    for rank, i in enumerate(np.argsort(p, kind="stable")):
        running = max(running, min(1.0, (m - rank) * p[i]))
        adjusted[i] = running
    return [float(v) for v in adjusted]


def seedsForFamily(tests, alpha=SIGNIFICANCE):
    """The fewest replicates whose exact sign-flip test can reach Holm's strictest threshold alpha / tests:
    all replicates agreeing give p = 2 / 2^n."""
    n = 1
    while 2.0 / 2.0 ** n > alpha / max(1, tests):
        n += 1
    return n


def seedsToConfirm(mean, sd, tests, alpha=SIGNIFICANCE):
    """A planning figure: the replicates at which a paired difference of this mean and standard deviation
    would reach alpha / tests (the strictest Holm step) by the normal approximation of its mean,
    n = (z sd / mean)^2, and never fewer than seedsForFamily(tests); None when the mean is 0."""
    floor = seedsForFamily(tests, alpha)
    if mean == 0:
        return None
    if sd == 0:
        return floor
    z = NormalDist().inv_cdf(1.0 - alpha / (2.0 * max(1, tests)))
    return max(floor, int(math.ceil((z * sd / abs(mean)) ** 2)))


def contrastPairs(arms):
    """The paired tests a study's report makes, (a, b, metric) for a minus b: ACCOUNT_PRIOR against NONE,
    IGNORE_PRIOR and ORACLE (the paper's question), then the control contrasts (controls.py), each
    where both arms ran."""
    pairs = [("ACCOUNT_PRIOR", b, "psnr") for b in ("NONE", "IGNORE_PRIOR", "ORACLE")
             if "ACCOUNT_PRIOR" in arms and b in arms]
    return pairs + [c for c in CONTROL_CONTRASTS + BANK_CONTRASTS if c[0] in arms and c[1] in arms]


def _bootstrapItem(ci, a, b, metric):
    """The bootstrap seed's item of a contrast: ACCOUNT_PRIOR's PSNR contrasts keep the item they had before
    the control arms existed, so earlier runs' intervals are reproduced."""
    if a == "ACCOUNT_PRIOR" and metric == "psnr" and ARMS.index(b) < 8:
        return (ci << 8) | ARMS.index(b)
    if ARMS.index(a) < 8 and ARMS.index(b) < 8:
        return (ci << 8) | 0x80 | (0x40 if metric != "psnr" else 0) | (ARMS.index(a) << 3) | ARMS.index(b)
    # Arms after the first eight do not fit three bits: items of their own, above every earlier one.
    return (ci << 16) | 0x8000 | (ARMS.index(a) << 8) | (0x80 if metric != "psnr" else 0) | ARMS.index(b)


def contrastRows(results):
    """Every paired test of a study (contrastPairs() in every condition): the mean difference and its s.d.,
    the 95% bootstrap interval, the sign-flip p, and, corrected by Holm over this study's tests
    (correctFamily()), the adjusted p and the verdict. With a single replicate there is no test (p None)."""
    baseSeed = int(results.get("config", {}).get("seed", 0))
    design = results.get("config", {}).get("design", "pooled")
    network = "told" if results.get("config", {}).get("noiseMaps", True) else "blind"
    rows = []
    for ci, entry in enumerate(results["conditions"]):
        arms = entry["arms"]
        for a, b, metric in contrastPairs(list(arms)):
            if metric not in arms[a] or metric not in arms[b]:
                continue
            diff = np.asarray(arms[a][metric]) - np.asarray(arms[b][metric])
            d, ds = _meanSd(diff)
            row = {"condition": entry["condition"]["name"], "priorShare": entry["priorShare"], "a": a, "b": b,
                   "metric": metric, "design": design, "network": network, "n": int(diff.size), "mean": d,
                   "sd": ds, "low": d, "high": d, "p": None}
            if diff.size >= 2:
                row["low"], row["high"], row["p"] = pairedSignificance(
                    diff, _seed(baseSeed, _ROLE_BOOTSTRAP, _bootstrapItem(ci, a, b, metric)))
            rows.append(row)
    return correctFamily(rows)


def correctFamily(rows):
    """Holm-corrects the p-values of `rows` (contrastRows' rows, of one study or of several) as one family:
    sets pHolm, the corrected verdict and its direction ("a", "b" or None), the family's size and the
    seeds that reaching SIGNIFICANCE after correction needs (seedsForFamily, and seedsToConfirm for each
    difference). Returns the rows."""
    tested = [r for r in rows if r["p"] is not None]
    for r, adjusted in zip(tested, holmAdjusted([r["p"] for r in tested])):
        r["pHolm"] = adjusted
    for r in rows:
        r["family"] = len(tested)
        r["seedsForFamily"] = seedsForFamily(len(tested))
        r["seedsToConfirm"] = seedsToConfirm(r["mean"], r["sd"], len(tested))
        if r["p"] is None:
            r["pHolm"], r["verdictHolm"], r["directionHolm"] = None, "n/a", None
            continue
        subject, words = (r["a"], ("better", "worse")) if r["metric"] == "psnr" else \
            ("%s's removed/noise" % r["a"], ("larger", "smaller"))
        r["verdict"] = _verdict(r["low"], r["high"], r["p"], subject, words)
        r["verdictHolm"] = _verdict(r["low"], r["high"], r["pHolm"], subject, words)
        decided = not (r["low"] <= 0 <= r["high"]) and r["pHolm"] <= SIGNIFICANCE
        r["directionHolm"] = ("a" if r["low"] > 0 else "b") if decided else None
    return rows


def summarize(results):
    """Per condition and arm: PSNR, SSIM and the implicit noise estimate (removed/noise), mean and standard
    deviation over the replicates, and for NONE, IGNORE_PRIOR and ORACLE the paired difference
    ACCOUNT_PRIOR minus the arm (replicate by replicate) with its significance (pairedSignificance()), its
    uncorrected verdict (_verdict(); 'n/a' with a single replicate) and its verdict after Holm's correction
    over the study's tests (contrastRows())."""
    contrasts = {(r["condition"], r["b"]): r for r in contrastRows(results)
                 if r["a"] == "ACCOUNT_PRIOR" and r["metric"] == "psnr"}
    rows = []
    for entry in results["conditions"]:
        for arm, runs in entry["arms"].items():
            p, ps = _meanSd(runs["psnr"])
            s, ss = _meanSd(runs["ssim"])
            row = {"condition": entry["condition"]["name"], "arm": arm, "psnr": p, "psnrSd": ps, "ssim": s,
                   "ssimSd": ss, "priorShare": entry["priorShare"], "photonRatio": entry["condition"]["photonRatio"],
                   "gainRatio": entry["condition"]["gainRatio"], "blurLength": entry["condition"]["blurLength"]}
            if "removedNoiseRatio" in runs:
                row["removed"], row["removedSd"] = _meanSd(runs["removedNoiseRatio"])
            c = contrasts.get((row["condition"], arm))
            if c is not None:
                row.update({"accountMinus": c["mean"], "accountMinusSd": c["sd"], "accountMinusLow": c["low"],
                            "accountMinusHigh": c["high"], "pValue": 1.0 if c["p"] is None else c["p"],
                            "verdict": c.get("verdict", "n/a"), "pHolm": c["pHolm"], "verdictHolm": c["verdictHolm"]})
            rows.append(row)
    return rows


def _plotScript(rows, arms):
    """A gnuplot script (data inline) against the photon ratio, one line per arm: PSNR on top and, below,
    the gain over the noisy input (where the arms' differences of tenths of a dB are visible); one column
    at the bright gain, one with the gain change, one for the blur condition. Without the NOISY arm there is
    no gain to draw: the PSNR row alone."""
    styles = {arm: i + 1 for i, arm in enumerate(ARMS)}
    panels = [("at the bright gain", lambda r: r["gainRatio"] == 1 and r["blurLength"] == 0),
              ("gain raised by 1/ratio (at most +12 dB)", lambda r: r["gainRatio"] > 1 and r["blurLength"] == 0),
              ("with motion blur", lambda r: r["blurLength"] > 0)]
    panels = [(title, test) for title, test in panels if any(test(r) for r in rows)]
    noisy = {r["condition"]: r["psnr"] for r in rows if r["arm"] == "NOISY"}
    measures = [("PSNR (dB)", lambda r: r["psnr"])]
    if noisy:
        measures.append(("PSNR gain over the noisy input (dB)", lambda r: r["psnr"] - noisy.get(r["condition"], math.nan)))
    lines = ["set terminal pngcairo size %d,%d enhanced font 'DejaVu Sans,11'" % (520 * len(panels), 500 * len(measures)),
             "set multiplot layout %d,%d title 'Denoiser on captures simulated at the target "
             "(mean and s.d. over seeds)'" % (len(measures), len(panels)),
             "set grid", "set logscale x", "set xrange [*:*] reverse",
             "set xlabel 'photon ratio of the target (darker to the right)'",
             "set offsets graph 0.08, graph 0.08, graph 0.05, graph 0.05"]
    for arm in arms:
        lines.append("set style line %d lw 2 pt %d ps 1.2" % (styles[arm], styles[arm] + 4))
    for row, (ylabel, value) in enumerate(measures):
        lines.append("set ylabel '%s'" % ylabel)
        lines.append("set key bottom left" if row == 0 else "set key right center")
        for title, test in panels:
            lines.append("set title '%s'" % title)
            plots = []
            for arm in arms:
                if row == 1 and arm == "NOISY":
                    continue
                data = sorted((r for r in rows if r["arm"] == arm and test(r)), key=lambda r: -r["photonRatio"])
                if not data:
                    continue
                block = "$%s_%d" % (arm.replace("_", ""), len(lines))
                lines.append("%s << EOD" % block)
                lines.extend("%.6g %.6f %.6f" % (r["photonRatio"], value(r), r["psnrSd"]) for r in data)
                lines.append("EOD")
                plots.append("%s using 1:2:3 with yerrorlines ls %d title '%s' noenhanced" % (block, styles[arm], arm))
            lines.append("plot " + ", ".join(plots))
    lines.append("unset multiplot")
    return "\n".join(lines) + "\n"


def _plotPng(rows, arms):
    """The PNG bytes of the plot, or None and the reason when gnuplot is missing or fails."""
    try:
        result = subprocess.run(["gnuplot"], input=_plotScript(rows, arms).encode(), capture_output=True)
    except FileNotFoundError:
        return None, "gnuplot is not installed (apt-get install gnuplot-nox): psnr.png was not drawn"
    if result.returncode != 0 or not result.stdout.startswith(b"\x89PNG"):
        return None, "gnuplot failed: " + result.stderr.decode(errors="replace").strip()
    return result.stdout, None


def _fmt(mean, sd, digits):
    return "%.*f ± %.*f" % (digits, mean, digits, sd)


def _report(results, rows, plotNote):
    config = results["config"]
    arms = config["arms"]
    m = config["model"]
    conditions = [entry["condition"]["name"] for entry in results["conditions"]]
    byKey = {(r["condition"], r["arm"]): r for r in rows}
    out = ["# Noise-alignment ablation: a RAW denoiser trained on each kind of darkened capture", ""]
    out.append("Sensor model: alpha = %.6g DN/e-, sigma_d^2 = %.6g DN^2, sigma_r^2 = %.6g DN^2 (quantisation "
               "included), %d bits, black level %g, bright captures at gain %g. %d training replicate(s) "
               "(seed %d), %d iterations of %d crops of %dx%d, tested on %d scenes of %dx%d simulated directly "
               "at each target. %d torch thread(s), torch %s, CPU path %s; %.0f s. The networks are %s." % (
                   m["alpha"], m["sigmaD2"], m["sigmaR2"], config["bitDepth"], config["blackLevel"],
                   config["baseGain"], config["seeds"], config["seed"], config["iterations"], config["batch"],
                   config["patch"], config["patch"], config["testScenes"], config["testSceneSize"],
                   config["testSceneSize"], config["threads"], results["torch"], results["cpuPath"],
                   results["seconds"],
                   "told the noise level (a noise map per plane)" if config.get("noiseMaps", True)
                   else "blind: they see the image only (--blind), residual step %g"
                   % config.get("blindStep", BLIND_STEP)))
    if (config.get("shotSampling", "GAUSSIAN"), config.get("priorMean", "PIXEL_VALUE")) != ("GAUSSIAN", "PIXEL_VALUE"):
        out += ["", "The augmented arms draw the shot part of their added noise as ShotNoiseSampling::%s and take "
                "the prior's level as PriorMeanEstimate::%s (the paper's: GAUSSIAN, PIXEL_VALUE)."
                % (config["shotSampling"], config["priorMean"])]
    extras = []
    if "rowSigmaD2" in m:
        extras.append("row noise %.4g g^2 + %.4g DN^2" % (m["rowSigmaD2"], m["rowSigmaR2"]))
    if "tukeyLambda" in m:
        extras.append("Tukey-lambda read noise (lambda %.3g)" % m["tukeyLambda"])
    if "darkShading" in m:
        extras.append("dark shading (maps %dx%d)" % (m["darkShading"][1], m["darkShading"][0]))
    if extras or config.get("camera"):
        out.append("")
        out.append(("The noise of the real camera '%s' (darktable's profiles). " % config["camera"]
                    if config.get("camera") else "") +
                   ("Dark-frame components in every capture and augmentation: %s." % ", ".join(extras)
                    if extras else ""))
    if config.get("departingSensor"):
        out += ["", "The simulated sensor departs from the model (--departing-sensor): 0.2%% hot and 1%% noisy pixels "
                "(100 DN^2 more), column banding of 2 DN^2 and a DSNU of 2 DN, which no model component describes; "
                "the bank arms draw their read part from %d dark captures per gain." % int(config.get("bankFrames", 25))]
    out += ["", "![PSNR against darkening](psnr.png)" if plotNote is None else "Plot: " + plotNote, ""]
    out += ["## PSNR (dB), mean ± s.d. over seeds", "",
            "| condition | prior share | " + " | ".join(arms) + " |",
            "|---|---|" + "---|" * len(arms)]
    for name in conditions:
        share = byKey[(name, arms[0])]["priorShare"]
        out.append("| %s | %.3f | " % (name, share) +
                   " | ".join(_fmt(byKey[(name, a)]["psnr"], byKey[(name, a)]["psnrSd"], 2) for a in arms) + " |")
    out += ["", "## SSIM, mean ± s.d. over seeds", "", "| condition | " + " | ".join(arms) + " |",
            "|---|" + "---|" * len(arms)]
    for name in conditions:
        out.append("| %s | " % name +
                   " | ".join(_fmt(byKey[(name, a)]["ssim"], byKey[(name, a)]["ssimSd"], 4) for a in arms) + " |")
    contrasts = contrastRows(results)
    if contrasts:
        out += ["", "## ACCOUNT_PRIOR minus each arm, the control and the dark-frame bank's contrasts (paired by "
                "seed)", ""]
        out += _testsTable(contrasts)
    if any("removed" in r for r in rows):
        trained = [a for a in arms if a in TRAINED_ARMS]
        out += ["", "## The networks' implicit noise estimate: removed / noise, mean ± s.d. over seeds", "",
                "The mean square of what each network removes from the test inputs (input minus output) over "
                "that of their true noise (input minus clean): 1 removes as much as the noise holds, below 1 "
                "the network takes the noise for less than it is, above 1 for more (or it removes signal too).",
                "", "| condition | " + " | ".join(trained) + " |", "|---|" + "---|" * len(trained)]
        for name in conditions:
            out.append("| %s | " % name + " | ".join(
                _fmt(byKey[(name, a)]["removed"], byKey[(name, a)]["removedSd"], 3) for a in trained) + " |")
    out += _predictionsSection(contrasts)
    out += ["", "## Reading it", ""]
    out += _findings(rows, conditions, arms)
    out += ["", "Prior share: the part of the target's noise variance (mid-grey green) that the darkened bright "
            "capture already carries. ACCOUNT_PRIOR adds only the rest; IGNORE_PRIOR adds the whole target "
            "variance again, so its inputs carry (1 + share) times the target's; NONE adds nothing, so its inputs "
            "carry only the share. Where the share is small, IGNORE_PRIOR and ACCOUNT_PRIOR should tie.", ""]
    return "\n".join(out)


def _findings(rows, conditions, arms):
    """Plain statements drawn from the numbers (never from expectations)."""
    byKey = {(r["condition"], r["arm"]): r for r in rows}
    lines = []
    if "ORACLE" in arms and "NOISY" in arms:
        beaten = [c for c in conditions if byKey[(c, "ORACLE")]["psnr"] > byKey[(c, "NOISY")]["psnr"]]
        lines.append("- The oracle beats the noisy input in %d of %d conditions%s." % (
            len(beaten), len(conditions),
            "" if len(beaten) == len(conditions) else
            " (not in: %s)" % ", ".join(c for c in conditions if c not in beaten)))
    if "ACCOUNT_PRIOR" not in arms:
        return lines
    for other in [a for a in ("NONE", "IGNORE_PRIOR", "ORACLE") if a in arms]:
        verdicts = {}
        for c in conditions:
            verdicts.setdefault(byKey[(c, other)].get("verdictHolm") or byKey[(c, other)]["verdict"], []).append(c)
        parts = ["%s in %s" % (v, ", ".join(cs)) for v, cs in sorted(verdicts.items())]
        lines.append("- ACCOUNT_PRIOR against %s (after Holm's correction): %s." % (other, "; ".join(parts)))
    return lines


def _cell(r):
    """A paired test as a table cell: mean [interval], p, Holm-corrected p and the corrected verdict."""
    if r["p"] is None:
        return "%+.3g (one seed: no test)" % r["mean"]
    return "%+.2f [%+.2f, %+.2f], p %.2g, Holm %.2g (%s)" % (r["mean"], r["low"], r["high"], r["p"], r["pHolm"],
                                                           r["verdictHolm"])


def _testsTable(contrasts):
    """The report's paired tests, one row each, with the family statement: how many tests, the seeds run
    and the seeds that reaching SIGNIFICANCE after Holm's correction needs."""
    family = contrasts[0]["family"]
    seeds = max(r["n"] for r in contrasts)
    out = ["Mean difference a minus b [95%% bootstrap interval over the paired seeds], the exact sign-flip "
           "test's two-sided p, and p corrected by Holm's method over all %d tests of this report (the "
           "family-wise error held at %g whatever the dependence between the tests: the conditions of a pooled "
           "network share one network). Verdict after correction: better or worse when the interval excludes "
           "0 and the corrected p is at most %g, leans when only the interval does, tie when the interval holds "
           "0. With n seeds p cannot fall below 2 / 2^n, so these %d tests need at least %d seeds, all agreeing, "
           "for any verdict; this run has %d. Seeds to confirm: the seeds at which a difference of this mean and "
           "spread would reach the strictest Holm step (normal approximation; a planning figure)."
           % (family, SIGNIFICANCE, SIGNIFICANCE, family, seedsForFamily(family), seeds), "",
           "| condition | prior share | a minus b | measure | difference | seeds to confirm |",
           "|---|---|---|---|---|---|"]
    for r in contrasts:
        out.append("| %s | %.3f | %s minus %s | %s | %s | %s |" % (
            r["condition"], r["priorShare"], r["a"], r["b"], "PSNR dB" if r["metric"] == "psnr" else "removed/noise",
            _cell(r), "-" if r["seedsToConfirm"] is None else r["seedsToConfirm"]))
    return out


def _predictionsSection(contrasts):
    """The control arms' predictions (controls.PREDICTIONS, stated before the runs) whose arms,
    network, design and conditions the contrasts hold, each with its outcome after the family's correction."""
    out = []
    for prediction in PREDICTIONS:
        scoped = [r for r in contrasts if r["network"] == prediction.network and r["design"] == prediction.design]
        outcome = predictionOutcome(prediction, scoped)
        if outcome is None:
            continue
        state, rows = outcome
        if not out:
            out = ["", "## The controls: predictions stated before the run, and outcomes", "",
                   "Each prediction was written into studies/ablation/rawgment_ablation/controls.py before the runs that test it; "
                   "the outcome is read from the Holm-corrected tests above: a direction holds when every "
                   "condition in its scope has that corrected verdict and is contradicted when any has the "
                   "other; a tie holds when none has a corrected verdict.", ""]
        out.append("- **%s** (%s networks, %s design). Hypothesis: %s Prediction: %s **Outcome: %s.** %s" % (
            prediction.name, prediction.network, prediction.design, prediction.hypothesis, prediction.text, state,
            "; ".join("%s: %s minus %s %s" % (r["condition"], r["a"], r["b"], _cell(r)) for r in rows)))
    return out


def _csv(rows):
    keys = ["condition", "arm", "photonRatio", "gainRatio", "blurLength", "priorShare", "psnr", "psnrSd", "ssim",
            "ssimSd", "removed", "removedSd", "accountMinus", "accountMinusSd", "accountMinusLow", "accountMinusHigh",
            "pValue", "verdict", "pHolm", "verdictHolm"]
    out = [",".join(keys)]
    for r in rows:
        out.append(",".join(("%.6g" % r[k]) if isinstance(r.get(k), float) else str(r.get(k, "")) for k in keys))
    return "\n".join(out) + "\n"


def writeOutputs(results, outDir):
    """Writes results.json, results.csv, psnr.png and report.md into outDir (created), each atomically.
    Returns the paths written and the notes (a plot that could not be drawn)."""
    os.makedirs(outDir, exist_ok=True)
    rows = summarize(results)
    png, note = _plotPng(rows, results["config"]["arms"])
    written = []

    def put(name, data):
        path = os.path.join(outDir, name)
        _rg.writeFileAtomically(path, data)
        written.append(path)

    put("results.json", (json.dumps(results, indent=1, sort_keys=True) + "\n").encode())
    put("results.csv", _csv(rows).encode())
    if png is not None:
        put("psnr.png", png)
    put("report.md", _report(results, rows, note).encode())
    return written, [] if note is None else [note]


#: The kinds of network the study trains: told the noise level (noise maps) or blind (the image only).
NETWORKS = ("told", "blind")


def studyName(network, design):
    """The folder of one study in a run of several: the network's name for the pooled design (as before
    the designs existed), "<network>-per-condition" for the other."""
    return network if design == "pooled" else "%s-%s" % (network, design)


def writeStudiesOutputs(byStudy, outDir):
    """Writes several studies (a dict from studyName() to runAblation's results: the kinds of network and the
    designs) into outDir/<study>/ (writeOutputs()) and, beside them, report.md: each condition's ACCOUNT_PRIOR
    minus the other trained arms and the control contrasts for every study side by side, Holm-corrected
    over all their tests together, and the control predictions' outcomes. Returns the paths written and
    the notes."""
    os.makedirs(outDir, exist_ok=True)
    written, notes, rowsOf = [], [], {}
    for name, results in byStudy.items():
        paths, more = writeOutputs(results, os.path.join(outDir, name))
        written += paths
        notes += ["%s: %s" % (name, n) for n in more]
        rowsOf[name] = summarize(results)
    path = os.path.join(outDir, "report.md")
    _rg.writeFileAtomically(path, _studiesReport(byStudy, rowsOf).encode())
    return written + [path], notes


def loadStudy(folder):
    """A study's results.json from its folder, checked for what the side-by-side page reads; a ValueError
    naming the file when it is missing or not a study's, or when an arm holds another number of values than
    the study's seeds (one value would otherwise be paired with every seed of another arm)."""
    path = os.path.join(folder, "results.json")
    try:
        with open(path, encoding="utf-8") as f:
            results = json.load(f)
        config = results["config"]
        if not isinstance(results["conditions"], list) or not results["conditions"] or "seeds" not in config:
            raise KeyError("conditions")
        seeds = config["seeds"]
        for entry in results["conditions"]:
            for arm, metrics in entry["arms"].items():
                for metric, values in metrics.items():
                    if not isinstance(values, list) or len(values) != seeds:
                        raise ValueError("'%s': condition %s, arm %s holds %s %s value(s) for its %d seed(s)" % (
                            path, entry["condition"]["name"], arm,
                            len(values) if isinstance(values, list) else "not a list of", metric, seeds))
    except OSError as e:
        raise ValueError("'%s' cannot be read: %s" % (path, e.strerror or e)) from None
    except ValueError as e:
        if str(e).startswith("'%s': condition" % path):
            raise
        raise ValueError("'%s' is not the results.json of a rawgment_ablation study (%s)" % (path, e)) from None
    except (KeyError, TypeError) as e:
        raise ValueError("'%s' is not the results.json of a rawgment_ablation study (%s)" % (path, e)) from None
    return results


#: What may differ between runs of one study that --combine merges: the replicates, the threads and the time.
_MERGEABLE = ("seeds", "firstReplicate", "threads", "replicates")


def mergeReplicates(runs):
    """One study from runs of it that differ only in their replicates (firstReplicate and seeds: the same
    base seed, sensor, scenes, arms, conditions and budget), each replicate once: every arm's numbers in
    replicate order, the seeds summed, the time summed, config["replicates"] the merged index ranges. A
    ValueError names what differs, or the replicate run twice."""
    def key(run):
        return {k: v for k, v in run["config"].items() if k not in _MERGEABLE}

    def conditions(run):
        return [entry["condition"] for entry in run["conditions"]]

    def names(run):
        return ", ".join(str(c.get("name")) for c in conditions(run))

    for run in runs[1:]:
        differing = sorted(k for k in set(key(run)) | set(key(runs[0])) if key(run).get(k) != key(runs[0]).get(k))
        if differing:
            raise ValueError("runs of one study differ in %s: only their replicates may" % ", ".join(differing))
        # The conditions are the study's too (they are not in its config): their order pairs the numbers.
        if conditions(run) != conditions(runs[0]):
            raise ValueError("runs of one study differ in their conditions (%s against %s): only their replicates "
                             "may" % (names(runs[0]), names(run)))
    ranges = sorted((r["config"].get("firstReplicate", 0), r["config"]["seeds"], i) for i, r in enumerate(runs))
    for (first, count, _), (nextFirst, _, _) in zip(ranges, ranges[1:]):
        if first + count > nextFirst:
            raise ValueError("two runs of one study both trained replicate %d" % nextFirst)
    ordered = [runs[i] for _, _, i in ranges]
    merged = json.loads(json.dumps(ordered[0]))
    for run in ordered[1:]:
        for entry, more in zip(merged["conditions"], run["conditions"]):
            for arm, values in entry["arms"].items():
                for metric in values:
                    values[metric] = values[metric] + more["arms"][arm][metric]
    merged["config"]["seeds"] = sum(r["config"]["seeds"] for r in runs)
    merged["config"]["replicates"] = [[first, first + count - 1] for first, count, _ in ranges]
    merged["seconds"] = sum(r["seconds"] for r in runs)
    return merged


def writeCombinedReport(folders, outDir):
    """The side-by-side page of studies written by separate runs (their folders, each with its
    results.json): outDir/report.md, Holm-corrected over all their tests together, linking to each study's
    own report. Runs of one network and design are merged into one study when they differ only in their
    replicates (mergeReplicates: a study extended with --first-replicate); otherwise they are refused,
    as are studies of different conditions and an existing report.md (ValueError). Returns its path."""
    runsOf, links = {}, {}
    for folder in folders:
        results = loadStudy(folder)
        config = results["config"]
        name = studyName("told" if config.get("noiseMaps", True) else "blind", config.get("design", "pooled"))
        runsOf.setdefault(name, []).append(results)
        links.setdefault(name, []).append(folder)
    byStudy = {}
    for name, runs in runsOf.items():
        try:
            byStudy[name] = mergeReplicates(runs) if len(runs) > 1 else runs[0]
        except ValueError as e:
            raise ValueError("%s (%s): %s" % (name, ", ".join("'%s'" % f for f in links[name]), e)) from None
    conditions = [[e["condition"] for e in r["conditions"]] for r in byStudy.values()]
    if any(c != conditions[0] for c in conditions):
        raise ValueError("the studies were run on different conditions: %s" % "; ".join(
            "%s: %s" % (n, ", ".join(c["name"] for c in cs)) for n, cs in zip(byStudy, conditions)))
    path = os.path.join(outDir, "report.md")
    if os.path.lexists(path):
        raise ValueError("'%s' exists: outputs are never replaced" % path)
    os.makedirs(outDir, exist_ok=True)
    relative = {n: [os.path.relpath(f, outDir) for f in fs] for n, fs in links.items()}
    _rg.writeFileAtomically(path, _studiesReport(byStudy, {n: summarize(r) for n, r in byStudy.items()},
                                                 relative).encode())
    return path


def _studiesReport(byStudy, rowsOf, folders=None):
    """The side-by-side page; `folders` maps each study to its folders relative to the page (default: its
    name, a subfolder; several for a study merged from several runs)."""
    folders = folders or {n: [n] for n in byStudy}
    names = list(byStudy)
    first = byStudy[names[0]]
    conditions = [entry["condition"]["name"] for entry in first["conditions"]]
    shares = {entry["condition"]["name"]: entry["priorShare"] for entry in first["conditions"]}
    contrastsOf = {n: contrastRows(byStudy[n]) for n in names}
    family = correctFamily([r for n in names for r in contrastsOf[n]])
    out = ["# Noise-alignment ablation: the studies side by side", "",
           "The same sensor, scenes, seeds and budget per network in every study; each has its own full report. "
           "A told network takes a noise-level map per plane beside the image; a blind one sees the image only, "
           "as the paper's detectors do. The pooled design trains one network per arm on all conditions (each "
           "crop draws its condition): it answers whether an arm's training set makes a better network for "
           "every exposure, and a difference it shows in one condition may be made in another. The "
           "per-condition design trains one network per arm and condition on that condition alone: it answers "
           "whether that condition's own inputs make the difference.", ""]
    for n in names:
        r = byStudy[n]
        ranges = r["config"].get("replicates")
        out.append("- **%s**: %s, %d seed(s)%s, %.0f s, CPU path %s." % (
            n, ", ".join("[%s/report.md](%s/report.md)" % (f, f) for f in folders[n]), r["config"]["seeds"],
            "" if not ranges else " (replicates %s, merged)" % ", ".join("%d-%d" % tuple(x) for x in ranges),
            r["seconds"], r["cpuPath"]))
    if family:
        tested = family[0]["family"]
        seeds = max(r["n"] for r in family)
        out += ["", "Every test below is corrected by Holm's method over all %d tests of this page together (the "
                "studies' own reports correct over their own tests only, so this page's verdicts are the "
                "stricter and the ones to quote). With n seeds the sign-flip p cannot fall below 2 / 2^n: %d "
                "tests need at least %d seeds, all agreeing, for any verdict; these studies have %d. Cells: mean "
                "difference [95%% bootstrap interval], p, Holm-corrected p (verdict after correction)."
                % (tested, tested, seedsForFamily(tested), seeds)]
    for title, pairs in (("ACCOUNT_PRIOR minus each arm, by study (PSNR dB, paired by seed)",
                          [(a, b, m) for a, b, m in {(r["a"], r["b"], r["metric"]) for r in family}
                           if a == "ACCOUNT_PRIOR" and m == "psnr"]),
                         ("The control contrasts, by study", list(dict.fromkeys(
                             (r["a"], r["b"], r["metric"]) for r in family
                             if (r["a"], r["b"], r["metric"]) in CONTROL_CONTRASTS))),
                         ("The dark-frame bank's contrasts, by study", list(dict.fromkeys(
                             (r["a"], r["b"], r["metric"]) for r in family
                             if (r["a"], r["b"], r["metric"]) in BANK_CONTRASTS)))):
        pairs = sorted(pairs, key=lambda c: ARMS.index(c[1])) if title.startswith("ACCOUNT") else pairs
        columns = [(n, c) for c in pairs for n in names
                   if any((r["a"], r["b"], r["metric"]) == c for r in contrastsOf[n])]
        if not columns:
            continue
        header = ["condition", "prior share"] + ["%s: %s" % (n, ("minus %s" % c[1]) if title.startswith("ACCOUNT")
                                                          else "%s minus %s%s" % (c[0], c[1], "" if c[2] == "psnr"
                                                                                  else " (removed/noise)"))
                                                 for n, c in columns]
        out += ["", "## " + title, "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        byKey = {(n, r["condition"], r["a"], r["b"], r["metric"]): r for n in names for r in contrastsOf[n]}
        for condition in conditions:
            cells = [condition, "%.3f" % shares[condition]]
            for n, c in columns:
                r = byKey.get((n, condition) + c)
                cells.append("-" if r is None else _cell(r))
            out.append("| " + " | ".join(cells) + " |")
    out += _predictionsSection(family)
    for n in names:
        # The findings read this page's family-corrected verdicts, not the study's own.
        corrected = {(r["condition"], r["b"]): r["verdictHolm"] for r in contrastsOf[n]
                     if r["a"] == "ACCOUNT_PRIOR" and r["metric"] == "psnr"}
        for row in rowsOf[n]:
            if (row["condition"], row["arm"]) in corrected:
                row["verdictHolm"] = corrected[(row["condition"], row["arm"])]
        out += ["", "## %s" % n, ""]
        out += _findings(rowsOf[n], conditions, byStudy[n]["config"]["arms"])
        out += ["", "![PSNR against darkening, %s](%s/psnr.png)" % (n, folders[n][0])]
    return "\n".join(out) + "\n"
