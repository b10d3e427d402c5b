// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * stop.js - the Stop button of a job's panel: the fit (fit.js) and the
 * experiments (experiment.js, loop.js). Shown always, it is enabled while
 * the panel follows a running job; a click ends the panel's polling, reads
 * the job once more and, if it is still running, sends its DELETE. A job
 * that had ended before the click is left as it is: the panel shows its
 * end as at any end, its message saying nothing was stopped.
 *
 * An experiment's fresh session, which the page asks the daemon to keep
 * for its plots (keep_session), stays when the plots follow it, its
 * controls the user's again; else the page deletes it too. A refused stop
 * is a message: after a 404 (the job is gone already) the panel is ready
 * for a new run, after any other it follows the job again.
 */

import * as api from './api.js';
import { app, $, message, report, setOnline, poll } from './ui.js';
import { detach, refreshSessionList } from './session.js';

/* The follower of the panel whose Stop button is sel and progress box
 * box; stop(j) ends job j (its DELETE and the message, default an
 * experiment's: stopExperiment) and is true once the job is gone.
 * follow(j, get, onUpdate) polls job j ({id, sessionId}) as ui.js poll
 * does, Stop enabled meanwhile, and returns the job's last answer once it
 * is over, or null once Stop has ended it. An answer whose job had ended
 * before Stop was pressed carries endedBeforeStop: true. */
export function stopButton(sel, box, stop = stopExperiment) {
	const button = $(sel);
	let running = null; /* the AbortController of the poll under way */
	button.disabled = true;
	button.addEventListener('click', () => {
		if (!running) return;
		button.disabled = true;
		running.abort();
	});
	return async function follow(j, get, onUpdate) {
		for (;;) {
			running = new AbortController();
			button.disabled = false;
			let end;
			try {
				end = await poll(get, j.id, onUpdate, running.signal);
			} finally {
				running = null;
				button.disabled = true;
			}
			if (end) return end;
			const ended = await endedAlready(j, get);
			if (ended) {
				onUpdate(ended);
				return { ...ended, endedBeforeStop: true };
			}
			/* The job may still end between that GET and the DELETE, a
			 * window of one round trip: its DELETE then forgets a job
			 * that had just ended. The daemon has no conditional DELETE
			 * to close it. */
			if (await stop(j)) {
				$(box).querySelector('.ptext').textContent = 'stopped';
				return null;
			}
		}
	};
}

/* Job j's answer if it has ended already (the page's last poll may
 * predate its end), else null: still running, or the GET failed (the
 * DELETE then says why). */
async function endedAlready(j, get) {
	try {
		const now = await get(j.id);
		setOnline(true);
		return now.done ? now : null;
	} catch {
		return null;
	}
}

/* The message at the end of experiment end, as the follower returns it. */
export function experimentEnded(end) {
	if (end.failed) message('error', `Experiment ${end.id} ${end.state}${end.error ? ': ' + end.error : ''}`);
	else if (end.endedBeforeStop) message('ok', `Experiment ${end.id} had already finished; nothing was stopped.`);
	else message('ok', `Experiment ${end.id} finished.`);
}

/* DELETE the fit; true once it is gone. */
export async function stopFit({ id }) {
	try {
		await api.deleteFit(id);
		setOnline(true);
	} catch (err) {
		report(err, 'Stop');
		return err instanceof api.ApiError && err.status === 404;
	}
	message('warn', `Fit ${id} stopped.`);
	return true;
}

/* DELETE the experiment, then see to its session: kept while the plots
 * follow it (and it still exists), else deleted. True once the experiment
 * is gone. */
async function stopExperiment({ id, sessionId }) {
	try {
		await api.deleteExperiment(id);
		setOnline(true);
	} catch (err) {
		report(err, 'Stop');
		return err instanceof api.ApiError && err.status === 404;
	}
	const removed = `Experiment ${id} stopped; its session was removed.`;
	if (!sessionId) {
		message('warn', `Experiment ${id} stopped.`);
	} else if (app.id === sessionId) {
		const s = await api.getSession(sessionId).catch(err => err);
		if (s instanceof api.ApiError && s.status === 404) {
			detach();
			message('warn', removed);
		} else {
			const how = s instanceof Error || !s.state || s.state === 'running' ? 'keeps running' : `stays (${s.state})`;
			message('warn', `Experiment ${id} stopped; session ${sessionId} ${how}.`);
		}
	} else {
		try {
			await api.deleteSession(sessionId);
			message('warn', removed);
		} catch (err) {
			if (err instanceof api.ApiError && err.status === 404) message('warn', removed);
			else { message('warn', `Experiment ${id} stopped.`); report(err, `Delete session ${sessionId}`); }
		}
	}
	refreshSessionList();
	return true;
}
