#!/usr/bin/env python3
"""Augments every RAW file of a folder N times with random noise-accounted scenes.

The same job as the rawgment_augment app (the same files, byte for byte), here from Python: in this
process, or on a local Dask cluster with --workers.

    /usr/bin/python3 samples/python/augment_folder.py --model camera.yml raws/ out/ [--variants 4] [--workers 2]
"""
import argparse
import os
import sys

import rawgment as rg
import rawgment.batch


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("folder", help="folder of RAW files (.dng, .nef, ...)")
    parser.add_argument("out", help="output folder")
    parser.add_argument("--model", required=True, help="the camera's noise model (.yml/.json)")
    parser.add_argument("--policy", help="a random policy file (default: the paper's ranges)")
    parser.add_argument("--variants", type=int, default=4)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=0, help="Dask worker processes (0: this process)")
    args = parser.parse_args()

    inputs = sorted(os.path.join(args.folder, n) for n in os.listdir(args.folder)
                    if os.path.splitext(n)[1].lower() in rawgment.batch.RAW_EXTENSIONS)
    if not inputs:
        sys.exit("no RAW file in %s" % args.folder)
    policy = args.policy
    if policy is None:
        os.makedirs(args.out, exist_ok=True)
        policy = os.path.join(args.out, "policy.yml")
        if not os.path.exists(policy):
            rg.RandomScenePolicy().save(policy)
    client = cluster = None
    if args.workers:
        from distributed import Client, LocalCluster

        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, dashboard_address=None)
        client = Client(cluster)
    try:
        result = rawgment.batch.augmentFiles(inputs, args.model, args.out, policy=policy, variants=args.variants,
                                             seed=args.seed, client=client)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    print("wrote %d, skipped %d finished earlier: %s" % (result["written"], result["skipped"], args.out))


if __name__ == "__main__":
    main()
