"""First import of every script: hand the job to the workflow's job server, if one is
up, before the script imports anything heavy (chain.pipeline.job_server).

Importing this module runs the job in the server and exits with its status; without a
server (a cluster job, ``HERTZCHAIN_JOB_SERVER=off``), or in the server, it does
nothing and the script goes on here, in a process that skips the final garbage
collections when it exits (chain.pipeline.run_end.freeze_at_exit: 0.4-0.5 s less for
a process that imported the job's libraries).
"""

import __main__
from chain.pipeline.job_server import hand_off
from chain.pipeline.run_end import freeze_at_exit

freeze_at_exit()
hand_off(getattr(__main__, "__real_file__", None))
