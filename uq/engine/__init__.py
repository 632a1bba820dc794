"""Running a study: the task store and the joblib / Dask runner, batch clusters (dask-jobqueue), and the execution of a
study from its plan to its tables."""
