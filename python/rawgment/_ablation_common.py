"""What rawgment.ablation and its report share: the arms, the seed roles and the blind network's step.
Private: import them from rawgment.ablation."""
import rawgment as _rg

ARMS = ("NONE", "IGNORE_PRIOR", "ACCOUNT_PRIOR", "ORACLE", "NOISY")
TRAINED_ARMS = ARMS[:4]
#: The arms of a run without --arms. NONE (no noise added) trails every other arm by 2 to 6 dB in every
#: condition (docs/results.md): it is left out so that 6 replicates of both kinds of network, the fewest
#: whose sign-flip test can reach p <= 0.05, fit the study's 30 minutes on 2 cores.
DEFAULT_ARMS = ("IGNORE_PRIOR", "ACCOUNT_PRIOR", "ORACLE", "NOISY")
# Roles of the derived seeds (the high 32 bits of deriveSeed's index under SEED_ABLATION).
(_ROLE_TRAIN_SCENES, _ROLE_TEST_SCENES, _ROLE_TEST_CAPTURE, _ROLE_BATCH, _ROLE_SAMPLE, _ROLE_NETWORK,
 _ROLE_BOOTSTRAP) = range(7)

#: The blind network's default residual unit: about the noise standard deviation of the study's
#: conditions on the network's scale (normalised planes). Unscaled, the first Adam steps moved the output
#: by far more than the noise, the ReLUs died and 11 of 12 trainings stayed the identity.
BLIND_STEP = 0.02


def _seed(base, role, item):
    """The seed of one item of a role: deriveSeed(deriveSeed(base, SEED_ABLATION, role), SEED_ABLATION, item)."""
    return _rg.deriveSeed(_rg.deriveSeed(int(base), _rg.SEED_ABLATION, int(role)), _rg.SEED_ABLATION, int(item))
