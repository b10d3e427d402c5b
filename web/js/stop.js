// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * stop.js - the Stop button of a job's panel: the fit (fit.js) and the
 * experiments (experiment.js, loop.js). Shown always, it is enabled while
 * the panel follows a running job; a click ends the panel's polling and
 * sends the job's DELETE only while it runs (?only=running). A job that
 * had ended before the DELETE came is kept by the daemon (409): the page
 * reads it and shows its end as at any end, its message saying nothing
 * was stopped.
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
 * box; stop(j) ends job j while it runs (its DELETE and the message,
 * default an experiment's: stopExperiment): true once the job is gone,
 * 'ended' where it had ended first, else false.
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
			const stopped = await stop(j);
			if (stopped === 'ended') {
				const ended = await endedAlready(j, get);
				if (ended) {
					onUpdate(ended);
					return { ...ended, endedBeforeStop: true };
				}
			} else if (stopped) {
				$(box).querySelector('.ptext').textContent = 'stopped';
				return null;
			}
		}
	};
}

/* Job j's answer once it has ended (the page's last poll may predate its
 * end), else null: the GET failed (the panel follows it again). */
async function endedAlready(j, get) {
	try {
		const now = await get(j.id);
		setOnline(true);
		return now.done ? now : null;
	} catch {
		return null;
	}
}

/* What a refused DELETE ?only=running means to stop(): 'ended' (409: the
 * job had ended first, and is kept), true (404: it is gone already) or
 * false (another refusal, said). */
function refusedStop(err) {
	if (err instanceof api.ApiError && err.status === 409) return 'ended';
	report(err, 'Stop');
	return err instanceof api.ApiError && err.status === 404;
}

/* The message at the end of experiment end, as the follower returns it. */
export function experimentEnded(end) {
	if (end.failed) message('error', `Experiment ${end.id} ${end.state}${end.error ? ': ' + end.error : ''}`);
	else if (end.endedBeforeStop) message('ok', `Experiment ${end.id} had already finished; nothing was stopped.`);
	else message('ok', `Experiment ${end.id} finished.`);
}

/* DELETE the fit while it runs; true once it is gone, 'ended' where it
 * had ended first. */
export async function stopFit({ id }) {
	try {
		await api.deleteFit(id, true);
		setOnline(true);
	} catch (err) {
		return refusedStop(err);
	}
	message('warn', `Fit ${id} stopped.`);
	return true;
}

/* DELETE the experiment while it runs, then see to its session: kept
 * while the plots follow it (and it still exists), else deleted. True once
 * the experiment is gone, 'ended' where it had ended first. */
async function stopExperiment({ id, sessionId }) {
	try {
		await api.deleteExperiment(id, true);
		setOnline(true);
	} catch (err) {
		return refusedStop(err);
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
