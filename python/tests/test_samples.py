"""The Python samples run to the end (short settings) and say what they promise."""
import os
import subprocess
import sys

import rawgment as rg


def run_sample(source_dir, name, *args, cwd=None):
    script = os.path.join(source_dir, "samples", "python", name)
    out = subprocess.run([sys.executable, script, *args], capture_output=True, text=True, cwd=cwd)
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_calibrate_simulated(source_dir, tmp_path):
    out = run_sample(source_dir, "calibrate_simulated.py", "--frames", "8", "--save", str(tmp_path / "m.yml"))
    alpha_line = next(line for line in out.splitlines() if line.startswith("alpha"))
    error = float(alpha_line.split()[-1].rstrip("%"))
    # ~55,000 pixels per gain, each variance of 7 degrees of freedom (relative SD sqrt(2/7) = 53%): the slope
    # of each gain is known to ~0.5% (0.53 / sqrt(55,000), times ~2 for the lever arm); 3% is ~6 of those.
    assert abs(error) < 3, out
    assert rg.NoiseModel.load(str(tmp_path / "m.yml")).alpha > 0


def test_augment_folder(source_dir, tmp_path, sensor, capture):
    (tmp_path / "raws").mkdir()
    rg.writeDng(str(tmp_path / "raws" / "x.dng"), rg.RawImage(mosaic=capture, format=sensor.rawFormat(1.0)))
    sensor.effectiveModel().save(str(tmp_path / "m.yml"))
    out = run_sample(source_dir, "augment_folder.py", "--model", str(tmp_path / "m.yml"), "--variants", "2",
                     str(tmp_path / "raws"), str(tmp_path / "out"))
    assert "wrote 2" in out
    assert sorted(os.listdir(tmp_path / "out")) == ["augment_job.yml", "policy.yml", "x_v00.dng", "x_v00.dng.yml", "x_v01.dng",
                                                    "x_v01.dng.yml"]


def test_torch_training_loop(source_dir):
    out = run_sample(source_dir, "torch_training_loop.py", "--steps", "12", "--workers", "2")
    first, last = [float(v.rstrip(",")) for v in out.splitlines()[-1].split()[2:5:2]]
    # The sample's promise: the loss falls (158 to 134 dB^2 in 12 steps with these seeds on this host).
    assert "step  12" in out and 0 < last < first
