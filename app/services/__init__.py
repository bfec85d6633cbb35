"""What the sessions of one server process share: the operator's settings (:mod:`.settings`),
the studies folder (:mod:`.studies_folder`), the study queue (:mod:`.study_queue`) and the
prioritized worker threads (:mod:`.thread_pools`).  May use ``model`` only.
"""
