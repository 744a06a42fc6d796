"""The ablation study of the paper's downstream claim (docs/ablation.md): small RAW denoisers trained on
darkened captures made with each arm's augmentation, compared on real-noise targets with paired
significance. Run it as ``python3 -m rawgment_ablation --help``. A study, not part of the library users
import: it lives in studies/ablation and is installed beside the ``rawgment`` package."""
