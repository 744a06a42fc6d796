"""The ablation's control arms and the predictions they test, written before the runs that answer them
(docs/ablation.md#the-control-arms): why blind networks trained on IGNORE_PRIOR's inputs did better than
those trained on ACCOUNT_PRIOR's. Each prediction names a paired contrast, the conditions it is about and
the direction expected; the report sets the Holm-corrected outcome beside it. Use it through
rawgment_ablation.study."""
import dataclasses

__all__ = ["Prediction", "PREDICTIONS", "CONTROL_CONTRASTS", "BANK_CONTRASTS", "predictionOutcome"]

#: The contrasts of the control arms, each (a, b, metric): a minus b, paired by replicate. The first three
#: isolate one change each; the last compares what the networks of the two alignments remove.
CONTROL_CONTRASTS = (("IGNORE_PRIOR", "IGNORE_RESCALED", "psnr"), ("ORACLE_PLUS_SHARE", "ORACLE", "psnr"),
                     ("ACCOUNT_POISSON", "ACCOUNT_PRIOR", "psnr"),
                     ("IGNORE_PRIOR", "ACCOUNT_PRIOR", "removedNoiseRatio"))

#: The dark-frame bank's contrasts: whether accounting matters for the read part (the bank accounted against
#: the peer's whole frames), and the bank against the parametric components and against the oracle.
BANK_CONTRASTS = (("DARK_BANK", "DARK_BANK_IGNORE", "psnr"), ("DARK_BANK", "ACCOUNT_PRIOR", "psnr"),
                  ("DARK_BANK", "ORACLE", "psnr"))

#: Where the prior share is large enough for IGNORE_PRIOR's excess variance to matter (x0.5 and x0.2 of the
#: default conditions: 0.48 and 0.17), and where it is negligible (x0.05 and x0.01: 0.028 and 0.002).
LARGE_SHARE = 0.1
SMALL_SHARE = 0.05


@dataclasses.dataclass(frozen=True)
class Prediction:
    """One stated prediction: contrast a minus b of `metric`, for `network` networks trained in `design`,
    in the conditions whose prior share is at least `shareAbove` (and below `shareBelow`), expected to be
    `expect`: "a" (a better, or larger), "b" or "tie" after Holm's correction."""
    name: str
    hypothesis: str
    a: str
    b: str
    metric: str
    network: str
    design: str
    shareAbove: float
    shareBelow: float
    expect: str
    text: str


#: Written on 2026-11-27, before the 12-seed runs of docs/results.md that test them.
PREDICTIONS = (
    Prediction("excess variance (rescaled)", "A blind network does better trained on more noise than the target's; "
               "IGNORE_PRIOR's lead is its (1 + share) times the target variance.",
               "IGNORE_PRIOR", "IGNORE_RESCALED", "psnr", "blind", "pooled", LARGE_SHARE, 2.0, "a",
               "IGNORE_PRIOR beats its own inputs rescaled to the target's variance where the share is large. "
               "A tie instead: the lead is not in how much noise IGNORE_PRIOR adds but in how it is made."),
    Prediction("excess variance (oracle)", "The same hypothesis, on real noise.",
               "ORACLE_PLUS_SHARE", "ORACLE", "psnr", "blind", "pooled", LARGE_SHARE, 2.0, "a",
               "Captures at the target plus the prior share of Gaussian noise beat plain captures where the share "
               "is large. A tie or a loss instead: extra variance is no gift, and IGNORE_PRIOR's level with the "
               "oracle is not explained by its excess."),
    Prediction("Gaussian shot draws", "ACCOUNT_PRIOR's Gaussian added noise (its skewness is low) is what it "
               "trails by.", "ACCOUNT_POISSON", "ACCOUNT_PRIOR", "psnr", "blind", "pooled", 0.0, 2.0, "tie",
               "A tie: exact Poisson draws change nothing (12 earlier seeds said so). A win for ACCOUNT_POISSON "
               "would make the noise's shape the mechanism after all."),
    Prediction("pooling", "The pooled network carries what it learns where the share is large into the "
               "conditions where it is negligible.", "ACCOUNT_PRIOR", "IGNORE_PRIOR", "psnr", "blind",
               "per-condition", 0.0, SMALL_SHARE, "tie",
               "Networks trained on one condition alone tie where the share is negligible (the two arms' inputs "
               "differ by under 3% of the variance there). A difference instead: it is made by the inputs of "
               "that condition itself, not carried over by pooling."),
    Prediction("pooling (oracle)", "The same: ACCOUNT_PRIOR's deficit against the oracle is made by pooling.",
               "ACCOUNT_PRIOR", "ORACLE", "psnr", "blind", "per-condition", 0.0, 2.0, "tie",
               "Networks trained on one condition alone: ACCOUNT_PRIOR ties the oracle in every condition. A loss "
               "instead: ACCOUNT_PRIOR's inputs lack something a capture has, pooled or not."),
    Prediction("implicit noise estimate", "Blind networks learn the noise level of their training inputs and "
               "remove that much.", "IGNORE_PRIOR", "ACCOUNT_PRIOR", "removedNoiseRatio", "blind", "pooled",
               LARGE_SHARE, 2.0, "a",
               "Blind IGNORE_PRIOR networks remove more from the test inputs (a larger removed/noise ratio) than "
               "ACCOUNT_PRIOR's where the share is large. No difference instead: what they remove does not "
               "follow their training variance."),
)


def predictionOutcome(prediction, contrasts):
    """The outcome of a prediction on a study's contrast rows (report.contrastRows, corrected):
    None when the study lacks its arms, design or conditions; else (state, rows) with state "held",
    "contradicted" or "undecided" and the rows it was read from. A direction held when every condition in
    scope has that corrected verdict, is contradicted when any has the other; a tie held when none has a
    corrected verdict and is contradicted when any has one. With fewer seeds than the family needs for any
    verdict (seedsForFamily), every prediction is undecided."""
    rows = [r for r in contrasts if (r["a"], r["b"], r["metric"]) == (prediction.a, prediction.b, prediction.metric)
            and prediction.shareAbove <= r["priorShare"] < prediction.shareBelow]
    if not rows:
        return None
    directions = [r["directionHolm"] for r in rows]
    if any(r["n"] < r["seedsForFamily"] for r in rows):
        # Too few seeds for any verdict after correction: a tie would be no evidence of one.
        return "undecided (too few seeds for any corrected verdict)", rows
    if prediction.expect == "tie":
        state = "contradicted" if any(d in ("a", "b") for d in directions) else "held"
    else:
        other = "b" if prediction.expect == "a" else "a"
        if any(d == other for d in directions):
            state = "contradicted"
        elif all(d == prediction.expect for d in directions):
            state = "held"
        else:
            state = "undecided"
    return state, rows
