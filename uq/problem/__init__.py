"""The problem a study poses: study files and their reader, parameter spaces, the models that simulate a run,
the method contract, tasks and run limits, cluster settings. Imports no method, figure or engine
(tests/test_architecture.py)."""
