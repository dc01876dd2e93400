"""The paper's experiments as commands: ``lbgp experiment sim | real-protocol | ablation``.

Each writes its table or figure under ``results/`` together with the command line that made it.
"""
