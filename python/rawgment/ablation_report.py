"""The report of rawgment.ablation: paired significance by sign-flip bootstrap, the summary rows, the PSNR
plot, report.md, results.json and results.csv, for one kind of network or both side by side. Use it through
rawgment.ablation."""
import json
import math
import os
import subprocess

import numpy as np

import rawgment as _rg
from rawgment._ablation_common import ARMS, BLIND_STEP, TRAINED_ARMS, _ROLE_BOOTSTRAP, _seed

__all__ = ["pairedSignificance", "summarize", "writeOutputs", "writeNetworksOutputs", "NETWORKS", "SIGNIFICANCE"]


def _meanSd(values):
    v = np.asarray(values, dtype=np.float64)
    return float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else 0.0


#: Resamples of the paired bootstrap interval of ACCOUNT_PRIOR minus an arm.
_BOOTSTRAP_RESAMPLES = 20000


def pairedSignificance(differences, seed):
    """The significance of paired differences (one per training replicate): the 95% percentile bootstrap
    interval of their mean (resampling replicates, from `seed`) and the exact two-sided sign-flip
    permutation p-value (every one of the 2^n sign patterns; a random 65536 of them above 16
    replicates). With n replicates the smallest p is 2 / 2^n: 0.25 at 3, 0.0625 at 5, 0.031 at 6."""
    d = np.asarray(differences, dtype=np.float64)
    n = d.size
    rng = np.random.default_rng(seed)
    means = d[rng.integers(0, n, size=(_BOOTSTRAP_RESAMPLES, n))].mean(axis=1)
    low, high = np.percentile(means, [2.5, 97.5])
    if n <= 16:
        signs = 1 - 2 * ((np.arange(2 ** n)[:, None] >> np.arange(n)) & 1)
    else:
        signs = rng.choice([-1, 1], size=(65536, n))
    flipped = np.abs((signs * d).mean(axis=1))
    p = float(np.mean(flipped >= abs(d.mean()) - 1e-12))
    return float(low), float(high), p


#: The sign-flip p at or below which a difference whose interval excludes 0 is a verdict, not a lean.
SIGNIFICANCE = 0.05


def _verdict(low, high, pValue):
    """'tie' when the 95% bootstrap interval holds 0; when it does not, 'ACCOUNT_PRIOR better' (or
    'worse') if the exact sign-flip p is at most SIGNIFICANCE too, else 'ACCOUNT_PRIOR leans better' (or
    'leans worse'). A percentile bootstrap over a handful of replicates is too narrow (3 replicates of
    one sign always give an interval off 0), so the interval alone never makes a verdict: with fewer than
    6 replicates p cannot reach 0.05 and the most a difference can do is lean."""
    if low <= 0 <= high:
        return "tie"
    direction = "better" if low > 0 else "worse"
    return "ACCOUNT_PRIOR " + (direction if pValue <= SIGNIFICANCE else "leans " + direction)


def summarize(results):
    """Per condition and arm: PSNR and SSIM mean and standard deviation over the replicates, and for
    each arm against ACCOUNT_PRIOR the paired difference (ACCOUNT_PRIOR minus the arm, replicate by
    replicate) with its significance (pairedSignificance()) and a verdict (_verdict(); 'n/a' with a
    single replicate)."""
    baseSeed = int(results.get("config", {}).get("seed", 0))
    rows = []
    for ci, entry in enumerate(results["conditions"]):
        arms = entry["arms"]
        for arm, runs in arms.items():
            p, ps = _meanSd(runs["psnr"])
            s, ss = _meanSd(runs["ssim"])
            row = {"condition": entry["condition"]["name"], "arm": arm, "psnr": p, "psnrSd": ps, "ssim": s,
                   "ssimSd": ss, "priorShare": entry["priorShare"], "photonRatio": entry["condition"]["photonRatio"],
                   "gainRatio": entry["condition"]["gainRatio"], "blurLength": entry["condition"]["blurLength"]}
            if "ACCOUNT_PRIOR" in arms and arm != "ACCOUNT_PRIOR":
                account = arms["ACCOUNT_PRIOR"]["psnr"]
                diff = np.asarray(account) - np.asarray(runs["psnr"])
                d, ds = _meanSd(diff)
                low, high, pValue = (d, d, 1.0)
                if len(account) < 2:
                    verdict = "n/a"
                else:
                    low, high, pValue = pairedSignificance(
                        diff, _seed(baseSeed, _ROLE_BOOTSTRAP, (ci << 8) | ARMS.index(arm)))
                    verdict = _verdict(low, high, pValue)
                row.update({"accountMinus": d, "accountMinusSd": ds, "accountMinusLow": low,
                            "accountMinusHigh": high, "pValue": pValue, "verdict": verdict})
            rows.append(row)
    return rows


def _plotScript(rows, arms):
    """A gnuplot script (data inline) against the photon ratio, one line per arm: PSNR on top and, below,
    the gain over the noisy input (where the arms' differences of tenths of a dB are visible); one column
    at the bright gain, one with the gain change, one for the blur condition. Without the NOISY arm there is
    no gain to draw: the PSNR row alone."""
    styles = {"NONE": 1, "IGNORE_PRIOR": 2, "ACCOUNT_PRIOR": 3, "ORACLE": 4, "NOISY": 5}
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
    others = [a for a in arms if a != "ACCOUNT_PRIOR"]
    if "ACCOUNT_PRIOR" in arms and others:
        out += ["", "## ACCOUNT_PRIOR minus each arm (PSNR dB, paired by seed)", "",
                "Mean difference [95%% bootstrap interval over the paired seeds], the exact sign-flip test's "
                "two-sided p and the verdict: better or worse when the interval excludes 0 and p <= %g, "
                "leans better or worse when the interval excludes 0 but p is larger, tie when the interval "
                "holds 0. With n seeds p cannot fall below 2 / 2^n (0.25 at 3 seeds, 0.0625 at 5, 0.031 "
                "at 6): fewer than 6 seeds can only lean." % SIGNIFICANCE, "",
                "| condition | " + " | ".join(others) + " |", "|---|" + "---|" * len(others)]
        for name in conditions:
            cells = []
            for a in others:
                r = byKey[(name, a)]
                cells.append("%+.2f [%+.2f, %+.2f], p %.3g (%s)" % (
                    r["accountMinus"], r["accountMinusLow"], r["accountMinusHigh"], r["pValue"], r["verdict"]))
            out.append("| %s | " % name + " | ".join(cells) + " |")
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
            verdicts.setdefault(byKey[(c, other)]["verdict"], []).append(c)
        parts = ["%s in %s" % (v, ", ".join(cs)) for v, cs in sorted(verdicts.items())]
        lines.append("- ACCOUNT_PRIOR against %s: %s." % (other, "; ".join(parts)))
    return lines


def _csv(rows):
    keys = ["condition", "arm", "photonRatio", "gainRatio", "blurLength", "priorShare", "psnr", "psnrSd", "ssim",
            "ssimSd", "accountMinus", "accountMinusSd", "accountMinusLow", "accountMinusHigh", "pValue", "verdict"]
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


def writeNetworksOutputs(byNetwork, outDir):
    """Writes one study per kind of network (a dict from NETWORKS' names to runAblation's results) into
    outDir/<network>/ (writeOutputs()) and, beside them, report.md: each condition's ACCOUNT_PRIOR minus
    the other trained arms for every network side by side, so the one page answers whether accounting
    matters when the network is told the noise level and when it is not. Returns the paths written and
    the notes."""
    os.makedirs(outDir, exist_ok=True)
    written, notes, rowsOf = [], [], {}
    for network, results in byNetwork.items():
        paths, more = writeOutputs(results, os.path.join(outDir, network))
        written += paths
        notes += ["%s: %s" % (network, n) for n in more]
        rowsOf[network] = summarize(results)
    path = os.path.join(outDir, "report.md")
    _rg.writeFileAtomically(path, _networksReport(byNetwork, rowsOf).encode())
    return written + [path], notes


def _networksReport(byNetwork, rowsOf):
    networks = list(byNetwork)
    first = byNetwork[networks[0]]
    config = first["config"]
    conditions = [entry["condition"]["name"] for entry in first["conditions"]]
    arms = config["arms"]
    others = [a for a in arms if a in TRAINED_ARMS and a != "ACCOUNT_PRIOR"]
    out = ["# Noise-alignment ablation: networks told the noise level and blind ones", "",
           "The same study (sensor, scenes, seeds, budget) run for each kind of network; each has its own "
           "full report. A told network takes a noise-level map per plane beside the image; a blind one "
           "sees the image only, as the paper's detectors do.", ""]
    for network in networks:
        r = byNetwork[network]
        out.append("- **%s**: [%s/report.md](%s/report.md), %d seed(s), %.0f s, CPU path %s." % (
            network, network, network, r["config"]["seeds"], r["seconds"], r["cpuPath"]))
    if "ACCOUNT_PRIOR" in arms and others:
        out += ["", "## ACCOUNT_PRIOR minus each arm, by network (PSNR dB, paired by seed)", "",
                "Mean difference [95%% bootstrap interval over the paired seeds], the exact sign-flip test's "
                "two-sided p and the verdict (better or worse: the interval excludes 0 and p <= %g; leans: "
                "the interval excludes 0, p is larger; tie: the interval holds 0)." % SIGNIFICANCE, ""]
        header = ["condition", "prior share"] + ["%s: minus %s" % (n, a) for a in others for n in networks]
        out += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        byKey = {n: {(r["condition"], r["arm"]): r for r in rowsOf[n]} for n in networks}
        for name in conditions:
            cells = [name, "%.3f" % byKey[networks[0]][(name, "ACCOUNT_PRIOR")]["priorShare"]]
            for a in others:
                for n in networks:
                    r = byKey[n][(name, a)]
                    cells.append("%+.2f [%+.2f, %+.2f], p %.3g (%s)" % (
                        r["accountMinus"], r["accountMinusLow"], r["accountMinusHigh"], r["pValue"],
                        r["verdict"]))
            out.append("| " + " | ".join(cells) + " |")
    for network in networks:
        out += ["", "## %s networks" % network.capitalize(), ""]
        out += _findings(rowsOf[network], conditions, arms)
        out += ["", "![PSNR against darkening, %s](%s/psnr.png)" % (network, network)]
    return "\n".join(out) + "\n"
