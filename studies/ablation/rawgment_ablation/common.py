"""What the ablation study (rawgment_ablation) and its report share: the arms, the seed roles and the blind network's step.
Private: import them from rawgment_ablation.study."""
import rawgment as _rg

#: The study's arms: the paper's three alignments, the oracle and the noisy floor, then the control arms that
#: take the blind result apart (docs/ablation.md#the-control-arms). New arms go at the end: an arm's index
#: seeds its bootstrap, so the earlier arms keep their numbers.
ARMS = ("NONE", "IGNORE_PRIOR", "ACCOUNT_PRIOR", "ORACLE", "NOISY", "IGNORE_RESCALED", "ORACLE_PLUS_SHARE",
        "ACCOUNT_POISSON", "DARK_BANK", "DARK_BANK_IGNORE")
#: The control arms: IGNORE_PRIOR's inputs with their noise scaled to the target's variance, the oracle's
#: captures with the prior share of extra Gaussian noise, ACCOUNT_PRIOR with exact Poisson shot draws.
CONTROL_ARMS = ARMS[5:8]
#: The dark-frame bank's arms (docs/dark_frame_bank.md): the read part drawn from real dark frames of the
#: sensor (a tied bank of its dark captures), accounted (ACCOUNT_PRIOR) or as whole frames on top of the
#: input's own (IGNORE_PRIOR: the peer's method); the shot part is the model's in both.
BANK_ARMS = ARMS[8:]
TRAINED_ARMS = tuple(a for a in ARMS if a != "NOISY")
#: The arms of a run without --arms. NONE (no noise added) trails every other arm by 2 to 6 dB in every
#: condition (docs/results.md): it is left out so that 6 replicates of both kinds of network, the fewest
#: whose sign-flip test can reach p <= 0.05, fit the study's 30 minutes on 2 cores.
DEFAULT_ARMS = ("IGNORE_PRIOR", "ACCOUNT_PRIOR", "ORACLE", "NOISY")
#: The training designs: one network per arm on every condition pooled (each crop draws its condition), or
#: one network per arm and condition, trained on that condition's inputs alone.
DESIGNS = ("pooled", "per-condition")
# Roles of the derived seeds (study_seed(study_seed(base, role), item)).
(_ROLE_TRAIN_SCENES, _ROLE_TEST_SCENES, _ROLE_TEST_CAPTURE, _ROLE_BATCH, _ROLE_SAMPLE, _ROLE_NETWORK,
 _ROLE_BOOTSTRAP, _ROLE_BANK) = range(8)

#: The blind network's default residual unit: about the noise standard deviation of the study's
#: conditions on the network's scale (normalised planes). Unscaled, the first Adam steps moved the output
#: by far more than the noise, the ReLUs died and 11 of 12 trainings stayed the identity.
BLIND_STEP = 0.02


#: The seed purpose the study derives under: 24, which rawgment's seeds.hpp keeps reserved for it (a study is
#: not part of the package, so the package names no purpose for it).
STUDY_SEED_PURPOSE = 24
_MASK = (1 << 64) - 1


def _step_key(seed, family):
    """The library's key mixing (src/random.hpp, stepKey): the SplitMix64 finaliser of seed + golden (family + 1),
    on which rawgment.deriveSeed(seed, purpose, index) = stepKey(stepKey(seed, purpose), index) is built."""
    z = (int(seed) + 0x9E3779B97F4A7C15 * (int(family) + 1)) & _MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    return z ^ (z >> 31)


def derive_seed(seed, purpose, index=0):
    """rawgment.deriveSeed of any purpose, the study's reserved one included."""
    return _step_key(_step_key(seed, purpose), index)


def study_seed(seed, index):
    """The study's seed of `index` under `seed`: deriveSeed(seed, 24, index)."""
    return derive_seed(seed, STUDY_SEED_PURPOSE, index)


def _seed(base, role, item):
    """The seed of one item of a role: study_seed(study_seed(base, role), item)."""
    return study_seed(study_seed(int(base), int(role)), int(item))
