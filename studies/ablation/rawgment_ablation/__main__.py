"""``python3 -m rawgment_ablation``: the study's command line (rawgment_ablation.study.main)."""
import sys

from rawgment_ablation.study import main

sys.exit(main())
